"""The Python client against a real deformd: load (phantom and file upload) with progress, list,
info with geometry, unload, poses in every accepted form, notices, and clear errors."""

import math
import pathlib
import tempfile
import unittest

import numpy as np

from deform_client import DeformClient, DeformError, pb
from deformd_process import DeformdProcess
from mesh_writers import write_obj, write_skeleton_json

STAGES = ["RECEIVED", "VALIDATED", "WEIGHTS", "FACTORISED", "READY"]


class BasicsTest(unittest.TestCase):
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

    def load_phantom(self, vertices=800, name="phantom"):
        stages = []
        summary = self.client.load_phantom(
            vertices, name=name, progress=lambda stage, ms: stages.append((stage, ms)))
        return summary, stages

    def test_load_phantom_reports_every_stage_in_order(self):
        summary, stages = self.load_phantom(800)
        self.assertEqual([stage for stage, _ in stages], STAGES)
        elapsed = [ms for _, ms in stages]
        self.assertEqual(elapsed, sorted(elapsed))
        self.assertTrue(summary.mesh_id.startswith("mesh-"), summary.mesh_id)
        self.assertGreater(summary.vertex_count, 500)
        self.assertIn("knee", [joint.name for joint in summary.joints])
        self.client.unload(summary.mesh_id)

    def test_list_info_and_unload(self):
        first, _ = self.load_phantom(600, name="first")
        second, _ = self.load_phantom(700, name="second")
        listed = [mesh.mesh_id for mesh in self.client.list_meshes()]
        self.assertLess(listed.index(first.mesh_id), listed.index(second.mesh_id))

        info = self.client.info(second.mesh_id, geometry=True)
        self.assertEqual(info.summary.name, "second")
        self.assertEqual(info.rest_positions.shape, (second.vertex_count, 3))
        self.assertEqual(info.rest_positions.dtype, np.float32)
        self.assertEqual(info.triangles.shape, (second.triangle_count, 3))
        self.assertLess(int(info.triangles.max()), second.vertex_count)
        self.assertTrue(np.all(np.isfinite(info.rest_positions)))
        plain = self.client.info(second.mesh_id)
        self.assertIsNone(plain.rest_positions)
        self.assertIsNone(plain.triangles)

        self.client.unload(first.mesh_id)
        listed = [mesh.mesh_id for mesh in self.client.list_meshes()]
        self.assertNotIn(first.mesh_id, listed)
        self.assertIn(second.mesh_id, listed)
        with self.assertRaises(DeformError) as raised:
            self.client.info(first.mesh_id)
        self.assertEqual(raised.exception.code_name, "NOT_FOUND")
        self.client.unload(second.mesh_id)

    def test_upload_of_files_in_small_chunks(self):
        phantom, _ = self.load_phantom(900)
        info = self.client.info(phantom.mesh_id, geometry=True)
        with tempfile.TemporaryDirectory() as directory:
            mesh = pathlib.Path(directory) / "leg.obj"
            skeleton = pathlib.Path(directory) / "leg.json"
            write_obj(mesh, info.rest_positions, info.triangles)
            write_skeleton_json(skeleton, phantom)
            chunked = DeformClient(self.server.target, upload_chunk_bytes=4096)
            self.assertGreater(mesh.stat().st_size, 10 * 4096)  # many chunks
            stages = []
            uploaded = chunked.load_files(mesh, skeleton,
                                          progress=lambda stage, ms: stages.append(stage))
            chunked.close()
        self.assertEqual(stages, STAGES)
        self.assertEqual(uploaded.name, "leg.obj")
        self.assertEqual(uploaded.vertex_count, phantom.vertex_count)
        self.assertEqual(uploaded.triangle_count, phantom.triangle_count)
        with self.client.stream(uploaded.mesh_id) as stream:
            stream.send_pose("knee:flexion:45")
            frame = stream.next_frame(timeout=30)
        self.assertEqual(frame.positions.shape, (phantom.vertex_count, 3))
        self.client.unload(uploaded.mesh_id)
        self.client.unload(phantom.mesh_id)

    def test_every_pose_form_gives_the_same_frame(self):
        summary, _ = self.load_phantom(600)
        forms = ["knee:flexion:60, knee:rotation:5",
                 [{"joint": "knee", "axis": "flexion", "degrees": 60},
                  {"joint": "knee", "axis": "rotation", "degrees": 5}],
                 [("knee", "flexion", 60), ("knee", "rotation", 5.0)],
                 pb.PoseUpdate(angles=[pb.JointAngle(joint="knee", axis="flexion", degrees=60),
                                       pb.JointAngle(joint="knee", axis="rotation",
                                                     degrees=5)])]
        frames = []
        with self.client.stream(summary.mesh_id) as stream:
            for form in forms:
                sequence = stream.send_pose(form)
                frame = stream.next_frame(timeout=30)
                self.assertEqual(frame.sequence, sequence)
                frames.append(frame.positions)
            stream.send_pose("rest")
            rest = stream.next_frame(timeout=30).positions
        for positions in frames[1:]:
            np.testing.assert_array_equal(positions, frames[0])
        self.assertGreater(float(np.abs(frames[0] - rest).max()), 0.1)
        self.client.unload(summary.mesh_id)

    def test_a_rejected_pose_arrives_as_a_notice_and_the_stream_goes_on(self):
        summary, _ = self.load_phantom(500)
        with self.client.stream(summary.mesh_id) as stream:
            bad = stream.send_pose(pb.PoseUpdate(
                angles=[pb.JointAngle(joint="knee", axis="flexion", degrees=math.nan)]))
            notice = stream.next_event(timeout=30)
            self.assertIsInstance(notice, pb.Notice)
            self.assertEqual(notice.kind, pb.Notice.KIND_POSE_REJECTED)
            self.assertEqual(notice.sequence, bad)
            good = stream.send_pose({"joint": "knee", "axis": "flexion", "degrees": 30})
            self.assertEqual(stream.next_frame(timeout=30).sequence, good)
        self.assertEqual(len(stream.notices), 1)
        self.client.unload(summary.mesh_id)

    def test_errors_are_clear(self):
        for call in (lambda: self.client.info("mesh-0000"),
                     lambda: self.client.unload("mesh-0000"),
                     lambda: self.client.stream("mesh-0000", encoding="float32")):
            with self.assertRaises(DeformError) as raised:
                call()
            self.assertEqual(raised.exception.code_name, "NOT_FOUND")
            self.assertIn("mesh-0000", str(raised.exception))
            self.assertTrue(str(raised.exception).startswith("NOT_FOUND: "),
                            str(raised.exception))
        with self.assertRaises(ValueError):
            self.client.load_files("leg.xyz", "leg.tgf")
        with self.assertRaises(FileNotFoundError):
            self.client.load_files("/nonexistent/leg.obj", "/nonexistent/leg.tgf")
        with self.assertRaises(ValueError):
            self.client.stream("mesh-0000", encoding="jpeg")
        with self.assertRaises(DeformError) as raised:
            self.client.load_phantom(-5)
        self.assertEqual(raised.exception.code_name, "INVALID_ARGUMENT")
        summary, _ = self.load_phantom(500)
        with self.client.stream(summary.mesh_id) as stream:
            for bad in ("knee:flexion", "knee:flexion:ninety", "knee:flexion:inf", ":x:1",
                        {"joint": "knee"}, 42):
                with self.assertRaises(ValueError):
                    stream.send_pose(bad)
            stream.send_pose("nosuchjoint:x:10")
            notice = stream.next_event(timeout=30)
            self.assertEqual(notice.kind, pb.Notice.KIND_POSE_REJECTED)
            self.assertIn("nosuchjoint", notice.message)
        with self.assertRaises(RuntimeError):
            stream.send_pose("knee:flexion:10")
        self.client.unload(summary.mesh_id)


if __name__ == "__main__":
    unittest.main()
