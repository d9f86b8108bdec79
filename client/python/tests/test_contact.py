"""Contact queries through the Python client against a real deformd: a sphere pressed into the
phantom's rest skin, a query against a Deform stream's latest frame, and bad input ending only
the query's own stream."""

import unittest

import numpy as np

from deform_client import DeformClient, DeformError
from deformd_process import DeformdProcess

# The 800-vertex phantom's thigh front is at y 6, z 0.66 (diagonal 8.97): a sphere of radius 0.3
# centred at z 0.86 is pressed about 0.1 into it.
SPHERE = "sphere:0,6,0.86,0.3"


class ContactTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.server = DeformdProcess("--workers", "2")
        cls.client = DeformClient(cls.server.target)
        if not cls.client.wait_for_ready(30):
            raise RuntimeError("deformd did not accept a connection")
        cls.mesh_id = cls.client.load_phantom(800).mesh_id

    @classmethod
    def tearDownClass(cls):
        cls.client.close()
        code = cls.server.stop()
        cls.server.__exit__()
        if code != 0:
            raise AssertionError(f"deformd exited {code} after SIGTERM")

    def test_a_sphere_pressed_into_the_rest_skin(self):
        with self.client.contact(self.mesh_id, stiffness=50) as contact:
            self.assertAlmostEqual(contact.started.bounding_box_diagonal, 8.97, delta=0.01)
            result = contact.query(SPHERE)
            self.assertEqual(result.sequence, 1)
            self.assertEqual(result.frame_number, 0)
            self.assertTrue(0.05 < result.depth < 0.15)
            normal = np.array([result.normal.x, result.normal.y, result.normal.z])
            force = np.array([result.force.x, result.force.y, result.force.z])
            self.assertGreater(normal[2], 0.7)
            expected = 50 * result.material_weight * result.depth / 8.97
            self.assertAlmostEqual(np.linalg.norm(force), expected, delta=0.01 * expected)
            apart = contact.query(("sphere", (0, 6, 1.86), 0.3))
            self.assertEqual(apart.sequence, 2)
            self.assertEqual(apart.depth, 0)

    def test_queries_follow_a_deform_streams_latest_frame(self):
        with self.client.stream(self.mesh_id) as stream:
            stream.send_pose("knee:flexion:80")
            frame = stream.next_frame(timeout=30)
            self.assertGreater(frame.message.stream_id, 0)
            vertex = frame.positions[len(frame.positions) // 2].astype(float)
            with self.client.contact(self.mesh_id, frame.message.stream_id) as contact:
                result = contact.query(("sphere", tuple(vertex), 0.05))
                self.assertEqual(result.frame_number, 1)
                self.assertEqual(result.frame_sequence, frame.sequence)
                self.assertLess(abs(result.signed_distance), 1e-5)

    def test_bad_input_raises_and_other_streams_go_on(self):
        with self.assertRaises(DeformError) as unknown:
            self.client.contact(self.mesh_id, deform_stream_id=987654)
        self.assertEqual(unknown.exception.code_name, "NOT_FOUND")
        contact = self.client.contact(self.mesh_id)
        with self.assertRaises(DeformError) as bad:
            contact.query(("sphere", (0, 6, 1), -1))
        self.assertEqual(bad.exception.code_name, "INVALID_ARGUMENT")
        with self.client.contact(self.mesh_id) as again:
            self.assertGreater(again.query(SPHERE).depth, 0)


if __name__ == "__main__":
    unittest.main()
