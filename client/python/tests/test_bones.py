"""Bone surfaces through the Python client: the phantom's three with their geometry, an upload's
surface files, frames' bone transforms and constraint reports, and constraints turned off."""

import tempfile
import unittest

import numpy as np

from deform_client import DeformClient, DeformError, pb
from deformd_process import DeformdProcess
from mesh_writers import write_obj, write_skeleton_json


class BonesTest(unittest.TestCase):
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

    def frame_at(self, mesh_id, pose):
        with self.client.stream(mesh_id) as stream:
            stream.send_pose(pose)
            return stream.next_frame(timeout=30)

    def test_phantom_bones_transforms_and_constraints(self):
        summary = self.client.load_phantom(2000)
        info = self.client.info(summary.mesh_id, geometry=True)
        self.assertEqual([s.name for s in info.bone_surfaces], ["femur", "tibia", "patella"])
        for surface, listed in zip(info.bone_surfaces, summary.bone_surfaces):
            self.assertEqual(surface.rest_positions.shape, (listed.vertex_count, 3))
            self.assertEqual(surface.triangles.shape, (listed.triangle_count, 3))
        frame = self.frame_at(summary.mesh_id, "knee:flexion:120")
        self.assertEqual(frame.bone_transforms.shape, (3, 3, 4))
        np.testing.assert_allclose(frame.bone_transforms[0, :, :3], np.eye(3), atol=1e-6)
        # The tibia turns by 120 degrees: its rotation's trace is 1 + 2 cos 120 = 0.
        self.assertAlmostEqual(float(np.trace(frame.bone_transforms[1, :, :3])), 0.0, places=5)
        self.assertIsNotNone(frame.constraints)
        self.assertEqual(frame.constraints.penetrating_after, 0)
        self.assertFalse(frame.constraints.unresolved)
        self.client.unload(summary.mesh_id)

    def test_constraints_off_and_a_phantom_without_bones(self):
        options = pb.MethodOptions(constraints=pb.Constraints(contacts=False, keep_volume=False))
        summary = self.client.load_phantom(800, options=options)
        self.assertFalse(summary.constraints.contacts)
        frame = self.frame_at(summary.mesh_id, "knee:flexion:120")
        self.assertEqual(frame.constraints.penetrating_after,
                         frame.constraints.penetrating_before)
        self.assertEqual(frame.constraints.contacts, 0)
        self.client.unload(summary.mesh_id)

        bare = self.client.load_phantom(800, bones=False)
        self.assertEqual(len(bare.bone_surfaces), 0)
        frame = self.frame_at(bare.mesh_id, "knee:flexion:60")
        self.assertEqual(frame.bone_transforms.shape, (0, 3, 4))
        self.client.unload(bare.mesh_id)

    def test_uploaded_bone_surfaces(self):
        phantom = self.client.load_phantom(1000)
        info = self.client.info(phantom.mesh_id, geometry=True)
        with tempfile.TemporaryDirectory() as folder:
            write_obj(f"{folder}/leg.obj", info.rest_positions, info.triangles)
            write_skeleton_json(f"{folder}/leg.json", phantom)
            femur = info.bone_surfaces[0]
            write_obj(f"{folder}/femur.obj", femur.rest_positions, femur.triangles)
            uploaded = self.client.load_files(f"{folder}/leg.obj", f"{folder}/leg.json",
                                              bone_surfaces=[f"{folder}/femur.obj:hip"])
            self.assertEqual([(s.name, s.bone) for s in uploaded.bone_surfaces], [("femur", 0)])
            with self.assertRaises(DeformError) as refused:
                self.client.load_files(f"{folder}/leg.obj", f"{folder}/leg.json",
                                       bone_surfaces=[(f"{folder}/femur.obj", "elbow")])
            self.assertEqual(refused.exception.code.name, "INVALID_ARGUMENT")
            self.assertIn("elbow", str(refused.exception))
            with self.assertRaises(ValueError):
                self.client.load_files(f"{folder}/leg.obj", f"{folder}/leg.json",
                                       bone_surfaces=[f"{folder}/femur.obj"])
        self.client.unload(uploaded.mesh_id)
        self.client.unload(phantom.mesh_id)


if __name__ == "__main__":
    unittest.main()
