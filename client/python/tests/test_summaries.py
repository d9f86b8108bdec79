"""The package's answers as typed objects and its version: a load, ListMeshes and GetMeshInfo
give the same MeshSummary (a frozen dataclass whose fields are the message's, with joints,
bones, bone surfaces, enums by name, warnings) that keeps its raw message; __version__ is
deformd's own (the top-level CMakeLists.txt, as `deformd --version` prints it)."""

import dataclasses
import re
import subprocess
import unittest

import deform_client
from deform_client import (Bone, BoneSurfaceInfo, DeformClient, DegreeOfFreedom, Joint,
                           MeshSummary, pb)
from deformd_process import DeformdProcess, deformd_program


class SummaryTest(unittest.TestCase):
    def test_summaries_are_typed_and_keep_their_message(self):
        with DeformdProcess("--workers", "1") as server, DeformClient(server.target) as client:
            loaded = client.load_phantom(900)
            listed = client.list_meshes()
            info = client.info(loaded.mesh_id)
        self.assertEqual(listed, [loaded])  # the message is left out of the comparison
        self.assertEqual(info.summary, loaded)
        for summary in (loaded, listed[0], info.summary):
            self.assertIsInstance(summary, MeshSummary)
            self.assertIsInstance(summary.message, pb.MeshSummary)
        message = loaded.message
        self.assertEqual(info.response.summary, message)
        self.assertEqual((loaded.mesh_id, loaded.name, loaded.vertex_count,
                          loaded.triangle_count, loaded.bone_count, loaded.factor_bytes),
                         (message.mesh_id, message.name, message.vertex_count,
                          message.triangle_count, message.bone_count, message.factor_bytes))
        self.assertGreater(loaded.vertex_count, 500)
        self.assertEqual(loaded.solved_vertex_count, loaded.vertex_count)
        self.assertEqual(loaded.warnings, tuple(message.warnings))
        self.assertEqual(loaded.binding, "THROUGH_BODY")
        self.assertEqual(loaded.rotation_blend, "QUATERNION")
        self.assertEqual([joint.name for joint in loaded.joints], ["hip", "knee", "ankle"])
        knee = loaded.joint("knee")
        self.assertIsInstance(knee, Joint)
        self.assertTrue(knee.has_region)
        self.assertEqual(len(knee.rest_position), 3)
        self.assertIsInstance(knee.dofs[0], DegreeOfFreedom)
        self.assertEqual(knee.dofs[0].name, "flexion")
        self.assertEqual(len(knee.dofs[0].axis), 3)
        self.assertLess(knee.dofs[0].min_degrees, knee.dofs[0].max_degrees)
        self.assertEqual(loaded.bones, (Bone(0, 1, -1), Bone(1, 2, 0)))
        self.assertEqual([surface.name for surface in loaded.bone_surfaces],
                         ["femur", "tibia", "patella"])
        self.assertIsInstance(loaded.bone_surfaces[0], BoneSurfaceInfo)
        self.assertGreater(loaded.bone_surfaces[0].triangle_count, 0)
        self.assertTrue(loaded.constraints.contacts)
        with self.assertRaises(dataclasses.FrozenInstanceError):
            loaded.name = "other"
        with self.assertRaises(KeyError) as raised:
            loaded.joint("elbow")
        self.assertIn("hip, knee, ankle", str(raised.exception))

    def test_the_version_is_deformds(self):
        printed = subprocess.run([str(deformd_program()), "--version"], capture_output=True,
                                 text=True, timeout=30).stdout
        match = re.match(r"deformd (\S+) ", printed)
        self.assertTrue(match, printed)
        self.assertEqual(deform_client.__version__, match.group(1))


if __name__ == "__main__":
    unittest.main()
