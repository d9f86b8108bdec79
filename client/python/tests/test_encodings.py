"""Every frame encoding decodes, through the Python decoders, within the error each frame states
of the frame the server sends in float32 for the same pose (as tests/service/frame_encoding_test.cc
checks the C++ client library), in fewer bytes; malformed frames are refused by name."""

import os
import pathlib
import subprocess
import tempfile
import unittest

import numpy as np

from deform_client import DeformClient, codec, pb
from deformd_process import REPOSITORY, DeformdProcess
from ply_files import read_ply

POSES = ["rest", "knee:flexion:30", "knee:flexion:90,knee:rotation:10",
         "knee:flexion:120,hip:flexion:20", "knee:flexion:60,ankle:x:-15"]


def frames_for(client, mesh_id, encoding, poses, max_error=0.0):
    frames = []
    with client.stream(mesh_id, encoding=encoding, max_error=max_error) as stream:
        for pose in poses:
            sequence = stream.send_pose(pose)
            frame = stream.next_frame(timeout=60)
            assert frame.sequence == sequence, (frame.sequence, sequence)
            frames.append(frame)
    return frames


def deform_vr_program():
    program = pathlib.Path(os.environ.get("DEFORM_TEST_DEFORM_VR",
                                          REPOSITORY / "build" / "client" / "vr" / "deform-vr"))
    if not program.is_file():
        raise RuntimeError(f"deform-vr not found at {program} (build it, or set "
                           f"DEFORM_TEST_DEFORM_VR)")
    return program


def excess_error(decoded, exact, stated):
    """The largest amount by which a decoded coordinate is farther from the float32 frame's than
    the stated error plus the float32 rounding of both (one unit in the last place of the value);
    <= 0 when every coordinate is within."""
    difference = np.abs(decoded.astype(np.float64) - exact.astype(np.float64))
    allowed = stated + np.spacing(np.abs(exact)).astype(np.float64)
    return float((difference - allowed).max())


class EncodingsTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.server = DeformdProcess("--workers", "2")
        cls.client = DeformClient(cls.server.target)

    @classmethod
    def tearDownClass(cls):
        cls.client.close()
        cls.server.__exit__()

    def check_encodings(self, mesh_id, bone_count, max_error=0.0):
        exact = frames_for(self.client, mesh_id, "float32", POSES)
        for frame in exact:
            self.assertEqual(frame.encoding, "float32")
            self.assertEqual(frame.positions.dtype, np.float32)
        for encoding in ("quantized", "predicted"):
            coded = frames_for(self.client, mesh_id, encoding, POSES, max_error)
            for pose, frame, reference in zip(POSES, coded, exact):
                with self.subTest(encoding=encoding, pose=pose):
                    self.assertEqual(frame.encoding, encoding)
                    self.assertEqual(frame.positions.shape, reference.positions.shape)
                    self.assertEqual(frame.positions.dtype, np.float32)
                    self.assertGreater(frame.max_error, 0)
                    self.assertLessEqual(excess_error(frame.positions, reference.positions,
                                                      frame.max_error), 0.0)
                    self.assertLess(2 * frame.wire_bytes, reference.wire_bytes)
                    transforms = len(frame.message.encoded.bone_transforms)
                    self.assertEqual(transforms, 12 * bone_count if encoding == "predicted"
                                     else 0)
        return exact

    def test_every_encoding_within_its_stated_error_for_both_blends(self):
        for blend in (pb.ROTATION_BLEND_QUATERNION, pb.ROTATION_BLEND_LINEAR):
            with self.subTest(blend=blend):
                summary = self.client.load_phantom(
                    2000, options=pb.MethodOptions(rotation_blend=blend))
                exact = self.check_encodings(summary.mesh_id, summary.bone_count)
                # The poses moved the mesh: the check compared real deformations.
                self.assertGreater(float(np.abs(exact[2].positions - exact[0].positions).max()),
                                   1.0)
                self.client.unload(summary.mesh_id)

    def test_frames_decode_bit_for_bit_as_the_cpp_client_library_decodes_them(self):
        # deform-vr decodes through the C++ client library (core/codec) and writes the frame as a
        # PLY of doubles (lossless); the server answers the same pose on the same mesh with the
        # same frame, so both decoders must give the same float32 bits.
        summary = self.client.load_phantom(2000)
        pose = "knee:flexion:75,knee:rotation:-8"
        for encoding in ("quantized", "predicted"):
            with self.subTest(encoding=encoding), tempfile.TemporaryDirectory() as directory:
                out = pathlib.Path(directory) / "frame.ply"
                done = subprocess.run(
                    [str(deform_vr_program()), "--target", self.server.target, "--mesh-id",
                     summary.mesh_id, "--encoding", encoding, "--pose", pose, "--frames", "1",
                     "--out", str(out)], capture_output=True, text=True, timeout=120)
                self.assertEqual(done.returncode, 0, done.stderr)
                cpp_positions, _ = read_ply(out)
                frame = frames_for(self.client, summary.mesh_id, encoding, [pose])[0]
                self.assertEqual(frame.encoding, encoding)
                np.testing.assert_array_equal(frame.positions,
                                              cpp_positions.astype(np.float32))
        self.client.unload(summary.mesh_id)

    def test_a_coarser_max_error_is_honoured_and_smaller(self):
        summary = self.client.load_phantom(2000)
        fine = frames_for(self.client, summary.mesh_id, "predicted", POSES[2:3])[0]
        coarse = frames_for(self.client, summary.mesh_id, "predicted", POSES[2:3], 1e-3)[0]
        exact = frames_for(self.client, summary.mesh_id, "float32", POSES[2:3])[0]
        self.assertGreater(coarse.max_error, 10 * fine.max_error)
        self.assertLess(coarse.wire_bytes, fine.wire_bytes)
        self.assertLessEqual(excess_error(coarse.positions, exact.positions, coarse.max_error), 0)
        self.client.unload(summary.mesh_id)

    def test_the_prediction_is_the_protos_float32_arithmetic(self):
        # A transform whose float32 products round differently from double ones: the prediction
        # must equal the operation-by-operation float32 evaluation of one vertex, bit for bit.
        rng = np.random.default_rng(7)
        rest = rng.uniform(-5, 5, (64, 3)).astype(np.float32)
        bones = rng.integers(0, 3, (64, 4))
        weights = rng.dirichlet(np.ones(4), 64).astype(np.float32)
        transforms = rng.uniform(-2, 2, (3, 12)).astype(np.float32)
        predicted = codec.predict_positions(rest, bones, weights, transforms)
        f = np.float32
        for i in range(64):
            p = [f(0), f(0), f(0)]
            for j in range(4):
                m = transforms[bones[i, j]]
                for r in range(3):
                    s = f(m[4 * r] * rest[i, 0])
                    s = f(s + f(m[4 * r + 1] * rest[i, 1]))
                    s = f(s + f(m[4 * r + 2] * rest[i, 2]))
                    s = f(s + m[4 * r + 3])
                    p[r] = f(p[r] + f(weights[i, j] * s))
            np.testing.assert_array_equal(predicted[i], np.array(p, dtype=np.float32))
        in_double = np.zeros((64, 3))
        for j in range(4):
            m = transforms[bones[:, j]].astype(np.float64).reshape(64, 3, 4)
            moved = np.einsum("vrc,vc->vr", m[:, :, :3], rest.astype(np.float64)) + m[:, :, 3]
            in_double += weights[:, j:j + 1] * moved
        self.assertTrue(np.any(in_double.astype(np.float32) != predicted),
                        "double arithmetic should round differently somewhere")

    def test_malformed_frames_are_refused_by_name(self):
        summary = self.client.load_phantom(500)
        info = self.client.info(summary.mesh_id, geometry=True, prediction_weights=True)
        n = summary.vertex_count
        quantized = codec.FrameDecoder(n)
        predicted = codec.FrameDecoder(n, info.response.rest_positions, info.prediction_weights)
        with self.assertRaisesRegex(ValueError, "do not decode"):
            quantized.decode_encoded(pb.EncodedPositions(
                encoding=pb.FRAME_ENCODING_QUANTIZED, origin=[0, 0, 0], step=0.1,
                data=b"\x00" * 10))
        with self.assertRaisesRegex(ValueError, "step"):
            quantized.decode_encoded(pb.EncodedPositions(
                encoding=pb.FRAME_ENCODING_QUANTIZED, origin=[0, 0, 0], step=0.0))
        with self.assertRaisesRegex(ValueError, "origin"):
            quantized.decode_encoded(pb.EncodedPositions(
                encoding=pb.FRAME_ENCODING_QUANTIZED, step=0.1))
        with self.assertRaisesRegex(ValueError, "prediction weights"):
            quantized.decode_encoded(pb.EncodedPositions(
                encoding=pb.FRAME_ENCODING_PREDICTED, step=0.1))
        with self.assertRaisesRegex(ValueError, "transform floats"):
            predicted.decode_encoded(pb.EncodedPositions(
                encoding=pb.FRAME_ENCODING_PREDICTED, step=0.1, bone_transforms=[1.0] * 5))
        with self.assertRaisesRegex(ValueError, "float32 frame"):
            codec.decode_float32(b"\x00" * 13, n)
        wrong = pb.PredictionWeights()
        wrong.CopyFrom(info.prediction_weights)
        wrong.num_bones = 1
        with self.assertRaisesRegex(ValueError, "out of range"):
            codec.FrameDecoder(n, info.response.rest_positions, wrong)
        self.client.unload(summary.mesh_id)


if __name__ == "__main__":
    unittest.main()
