"""A Deform stream that survives the loss of its server, against real deformd replicas.

Replica A and then replica B share a store (--store DIR --store-shared --store-key KEY, the key
outside DIR) and one fixed port, as two replicas behind one balancer address would. A loads the
phantom and the stream runs on it; A is killed (SIGKILL) and B starts on the same port. A stream
opened with reconnect=True goes on: its frames resume from B (which builds the mesh from the
store when the re-opened stream first names it, answering UNAVAILABLE with a RetryInfo
meanwhile), for the pose it had before, with stream.reconnects and on_reconnect counting at least
one re-opened call and no exception reaching the caller. Without reconnect the same kill ends the
stream with DeformError UNAVAILABLE. The asyncio stream survives it as the blocking one does."""

import asyncio
import pathlib
import tempfile
import time
import unittest

import grpc
import numpy as np

from deform_client import AsyncDeformClient, DeformClient, DeformError
from deformd_process import DeformdProcess, free_port

POSE = "knee:flexion:35"
RESUME_SECONDS = 30.0  # bound on the wait for B's frames (the policy gives up after 10 s)


class Replicas:
    """Starts replica A (replace() kills it and starts B) on one port and one shared store."""

    def __init__(self):
        self._dir = tempfile.TemporaryDirectory(prefix="deform-failover-")
        root = pathlib.Path(self._dir.name)
        self.flags = ("--store", root / "store", "--store-shared",
                      "--store-key", root / "store.key")
        self.listen = f"127.0.0.1:{free_port()}"
        self.server = DeformdProcess(*self.flags, listen=self.listen)
        self.target = self.server.target

    def replace(self):
        self.server.kill()
        self.server.__exit__()
        self.server = DeformdProcess(*self.flags, listen=self.listen)

    def close(self):
        self.server.__exit__()
        self._dir.cleanup()


class FailoverTest(unittest.TestCase):
    def setUp(self):
        self.replicas = Replicas()
        self.addCleanup(self.replicas.close)
        self.client = DeformClient(self.replicas.target)
        self.addCleanup(self.client.close)
        self.assertTrue(self.client.wait_for_ready(30))
        self.mesh = self.client.load_phantom(progress=None)

    def first_frame(self, stream):
        stream.send_pose(POSE)
        frame = stream.next_frame(timeout=30)
        self.assertIsNotNone(frame)
        return frame

    def test_a_reconnecting_stream_resumes_on_the_replacement(self):
        losses = []
        stream = self.client.stream(self.mesh.mesh_id, reconnect=True,
                                    on_reconnect=lambda loss, attempt: losses.append(loss))
        before = self.first_frame(stream)
        self.replicas.replace()
        resumed = None
        deadline = time.monotonic() + RESUME_SECONDS
        while resumed is None and time.monotonic() < deadline:
            sequence = stream.send_pose(POSE)
            try:
                frame = stream.next_frame(timeout=0.5)
            except TimeoutError:
                continue
            if frame is not None and frame.sequence == sequence:
                resumed = frame
        self.assertIsNotNone(resumed, "no frame from the replacement replica")
        self.assertGreaterEqual(stream.reconnects, 1)
        self.assertEqual(len(losses), stream.reconnects)
        self.assertEqual({loss.code for loss in losses}, {grpc.StatusCode.UNAVAILABLE})
        # B's first answer naming the mesh: UNAVAILABLE with a RetryInfo while it built it.
        self.assertTrue(any(loss.retry_delay > 0 for loss in losses),
                        [(loss.details, loss.retry_delay) for loss in losses])
        # B built the same content under the same id: the same pose deforms it alike.
        np.testing.assert_allclose(resumed.positions, before.positions, atol=1e-4)
        stream.close()  # ends well: no exception
        self.assertIn("built from the store", self.replicas.server.output())

    def test_without_reconnect_the_loss_ends_the_stream(self):
        stream = self.client.stream(self.mesh.mesh_id)
        self.first_frame(stream)
        self.replicas.replace()
        with self.assertRaises(DeformError) as raised:
            deadline = time.monotonic() + RESUME_SECONDS
            while time.monotonic() < deadline:
                try:
                    stream.send_pose(POSE)
                except RuntimeError:
                    pass  # ended: the next event raises why
                try:
                    stream.next_frame(timeout=0.5)
                except TimeoutError:
                    pass
        self.assertEqual(raised.exception.code, grpc.StatusCode.UNAVAILABLE)
        self.assertEqual(stream.reconnects, 0)

    def test_the_async_stream_resumes_too(self):
        async def run():
            async with AsyncDeformClient(self.replicas.target) as client:
                stream = await client.stream(self.mesh.mesh_id, reconnect=True)
                await stream.send_pose(POSE)
                self.assertIsNotNone(await stream.next_frame(timeout=30))
                self.replicas.replace()
                loop = asyncio.get_running_loop()
                deadline = loop.time() + RESUME_SECONDS
                while loop.time() < deadline:
                    sequence = await stream.send_pose(POSE)
                    try:
                        frame = await stream.next_frame(timeout=0.5)
                    except TimeoutError:
                        continue
                    if frame is not None and frame.sequence == sequence:
                        reconnects = stream.reconnects
                        await stream.close()
                        return reconnects
                return None
        reconnects = asyncio.run(run())
        self.assertIsNotNone(reconnects, "no frame from the replacement replica")
        self.assertGreaterEqual(reconnects, 1)


if __name__ == "__main__":
    unittest.main()
