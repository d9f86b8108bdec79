"""Tools through the Python client against a real deformd: a sphere pressed into the phantom's
thigh leaves no skin inside it, lifting it gives back the tool-free frame, and bad tools are
rejected with a notice while the stream goes on."""

import unittest

import numpy as np

from deform_client import DeformClient, pb, tool_state
from deformd_process import DeformdProcess

# The 800-vertex phantom's thigh front is at y 6, z 0.66 (diagonal 8.97): a sphere of radius 0.3
# centred at z 0.86 is pressed about 0.1 into it.
SPHERE = "sphere:0,6,0.86,0.3"
DIAGONAL = 8.97


class ToolsTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.server = DeformdProcess("--workers", "2")
        cls.client = DeformClient(cls.server.target)
        if not cls.client.wait_for_ready(30):
            raise RuntimeError("deformd did not accept a connection")

    @classmethod
    def tearDownClass(cls):
        cls.client.close()
        code = cls.server.stop()
        cls.server.__exit__()
        if code != 0:
            raise AssertionError(f"deformd exited {code} after SIGTERM")

    def test_a_sphere_presses_and_lifts(self):
        summary = self.client.load_phantom(800)
        with self.client.stream(summary.mesh_id) as stream:
            stream.send_pose("knee:flexion:30")
            free = stream.next_frame(timeout=30)
            stream.send_pose("knee:flexion:30", tools=SPHERE)
            pressed = stream.next_frame(timeout=30)
            stream.send_pose("knee:flexion:30")
            lifted = stream.next_frame(timeout=30)
        c = pressed.constraints
        self.assertGreater(c.tool_penetrating_before, 0)
        self.assertEqual(c.tool_penetrating_after, 0)
        self.assertLessEqual(c.tool_max_depth_after, 1e-4 * DIAGONAL)
        self.assertGreater(c.tool_contacts, 0)
        self.assertFalse(c.tools_unresolved)
        moved = np.linalg.norm(pressed.positions - free.positions, axis=1)
        self.assertGreater(moved.max(), 0.05)
        # Positions are float32 on the wire: the tool-free frame comes back bit for bit.
        np.testing.assert_array_equal(lifted.positions, free.positions)
        self.assertEqual(lifted.constraints.tool_contacts, 0)
        self.client.unload(summary.mesh_id)

    def test_bad_tools_are_rejected_and_the_stream_goes_on(self):
        summary = self.client.load_phantom(800)
        too_many = [SPHERE] * 5
        bad = pb.ToolState(shape=pb.ToolState.SHAPE_SPHERE, center=pb.Vector3(x=0, y=6, z=1),
                           radius=-1)
        with self.client.stream(summary.mesh_id) as stream:
            for tools in (too_many, [bad]):
                stream.send_pose("rest", tools=tools)
                notice = stream.next_event(timeout=30)
                self.assertIsInstance(notice, pb.Notice)
            stream.send_pose("rest", tools=tool_state(("sphere", (0, 6, 0.86), 0.3)))
            frame = stream.next_frame(timeout=30)
        self.assertGreater(frame.constraints.tool_penetrating_before, 0)
        rejected = [n for n in stream.notices if n.kind == pb.Notice.KIND_POSE_REJECTED]
        self.assertEqual(len(rejected), 2, [n.message for n in stream.notices])
        self.assertIn("at most 4 tools", rejected[0].message)
        self.assertIn("radius", rejected[1].message)
        self.client.unload(summary.mesh_id)

    def test_malformed_tool_text_is_a_value_error(self):
        for text in ("sphere:1,2,3", "cube:0,0,0,1", "sphere:0,0,nan,1"):
            with self.assertRaises(ValueError):
                tool_state(text)


if __name__ == "__main__":
    unittest.main()
