"""Deadlines on every call against a real deformd: a load past its `timeout=` fails with
DeformError DEADLINE_EXCEEDED and the server stops building it (its log says so, nothing is
listed) and goes on serving; info, list_meshes and unload fail the same way when the server
answers nothing in their timeout (the process stopped with SIGSTOP), as does every call of a
client whose unary_timeout and load_timeout are short; a stream past its deadline ends with
DEADLINE_EXCEEDED; timeout=None is no deadline; a negative timeout is a ValueError."""

import time
import unittest

import grpc

from deform_client import DEFAULT_LOAD_TIMEOUT, DEFAULT_UNARY_TIMEOUT, DeformClient, DeformError
from deformd_process import DeformdProcess


def wait_for(predicate, seconds=10.0):
    deadline = time.monotonic() + seconds
    while not predicate():
        if time.monotonic() > deadline:
            return False
        time.sleep(0.02)
    return True


class TimeoutTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.server = DeformdProcess("--workers", "2")
        cls.client = DeformClient(cls.server.target)
        if not cls.client.wait_for_ready(30):
            raise RuntimeError("deformd did not accept a connection")

    @classmethod
    def tearDownClass(cls):
        cls.client.close()
        cls.server.__exit__()

    def assertDeadlineExceeded(self, call):
        with self.assertRaises(DeformError) as raised:
            call()
        self.assertEqual(raised.exception.code, grpc.StatusCode.DEADLINE_EXCEEDED)
        self.assertEqual(raised.exception.code_name, "DEADLINE_EXCEEDED")
        self.assertTrue(str(raised.exception).startswith("DEADLINE_EXCEEDED: "))

    def test_the_defaults_are_stated(self):
        self.assertEqual(DEFAULT_UNARY_TIMEOUT, 30.0)
        self.assertEqual(DEFAULT_LOAD_TIMEOUT, 600.0)

    def test_a_load_past_its_timeout_is_cancelled_on_the_server(self):
        before = [mesh.mesh_id for mesh in self.client.list_meshes()]
        started = time.monotonic()
        # 20,000 vertices take about a second to build here: 50 ms is far too short.
        self.assertDeadlineExceeded(lambda: self.client.load_phantom(20000, timeout=0.05))
        self.assertLess(time.monotonic() - started, 5.0)
        self.assertTrue(wait_for(lambda: "build stopped: cancelled" in self.server.output()),
                        self.server.output()[-2000:])
        self.assertEqual([mesh.mesh_id for mesh in self.client.list_meshes()], before)
        # The server goes on serving; timeout=None is no deadline.
        summary = self.client.load_phantom(600, timeout=None)
        self.assertEqual(summary.vertex_count, self.client.info(summary.mesh_id).summary
                         .vertex_count)
        self.client.unload(summary.mesh_id)

    def test_calls_to_a_server_that_answers_nothing_end_at_their_timeout(self):
        # A server of its own: what it does with the calls after it continues is not asserted.
        with DeformdProcess("--workers", "1") as server:
            client = DeformClient(server.target)
            summary = client.load_phantom(500, timeout=60)
            hurried = DeformClient(server.target, unary_timeout=0.2, load_timeout=0.2)
            self.assertTrue(hurried.wait_for_ready(30))
            with server.paused():  # it answers nothing until the block ends
                started = time.monotonic()
                self.assertDeadlineExceeded(lambda: client.info(summary.mesh_id, timeout=0.2))
                self.assertDeadlineExceeded(lambda: client.list_meshes(timeout=0.2))
                self.assertDeadlineExceeded(lambda: client.unload("mesh-0000", timeout=0.2))
                self.assertDeadlineExceeded(lambda: client.load_phantom(500, timeout=0.2))
                self.assertDeadlineExceeded(hurried.list_meshes)
                self.assertDeadlineExceeded(lambda: hurried.info(summary.mesh_id))
                self.assertDeadlineExceeded(lambda: hurried.load_phantom(500))
                self.assertLess(time.monotonic() - started, 7 * 0.2 + 3.0)
            # A call's own timeout overrides the client's.
            self.assertEqual(hurried.info(summary.mesh_id, timeout=30).summary.mesh_id,
                             summary.mesh_id)
            hurried.close()
            client.close()

    def test_a_stream_past_its_deadline_ends_with_deadline_exceeded(self):
        summary = self.client.load_phantom(500)
        stream = self.client.stream(summary.mesh_id, timeout=1.0)
        stream.send_pose("knee:flexion:30")
        self.assertEqual(stream.next_frame(timeout=30).sequence, 1)
        with self.assertRaises(DeformError) as raised:
            stream.next_frame(timeout=30)  # no pose: the deadline comes first
        self.assertEqual(raised.exception.code_name, "DEADLINE_EXCEEDED")
        self.client.unload(summary.mesh_id)

    def test_a_negative_timeout_is_refused(self):
        with self.assertRaises(ValueError):
            self.client.list_meshes(timeout=-1)
        with self.assertRaises(ValueError):
            DeformClient(self.server.target, load_timeout=-5)


if __name__ == "__main__":
    unittest.main()
