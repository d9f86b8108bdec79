"""AsyncDeformClient against a real deformd: load with progress, list, info with geometry,
unload, streams in every encoding iterated with `async for` whose frames equal the blocking
client's for the same poses (within 1e-6), two streams at once on one event loop, notices, the
errors the blocking client raises (NOT_FOUND, DEADLINE_EXCEEDED for a load past its timeout),
and a stream past its deadline."""

import asyncio
import unittest

import numpy as np

from deform_client import AsyncDeformClient, DeformClient, DeformError, Frame, MeshSummary, pb
from deformd_process import DeformdProcess

STAGES = ["RECEIVED", "VALIDATED", "WEIGHTS", "FACTORISED", "READY"]
POSES = ["knee:flexion:30", "knee:flexion:90,knee:rotation:10", "rest"]


def blocking_frames(target, mesh_id, encoding):
    with DeformClient(target) as client, client.stream(mesh_id, encoding=encoding) as stream:
        frames = []
        for pose in POSES:
            stream.send_pose(pose)
            frames.append(stream.next_frame(timeout=30).positions)
        return frames


class AsyncClientTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.server = DeformdProcess("--workers", "2")

    @classmethod
    def tearDownClass(cls):
        cls.server.__exit__()

    def run_async(self, coroutine):
        return asyncio.run(asyncio.wait_for(coroutine, 60))

    def test_load_list_info_unload(self):
        async def session():
            async with AsyncDeformClient(self.server.target) as client:
                self.assertTrue(await client.wait_for_ready(30))
                stages = []
                summary = await client.load_phantom(
                    800, name="async", progress=lambda stage, ms: stages.append(stage))
                self.assertEqual(stages, STAGES)
                self.assertIsInstance(summary, MeshSummary)
                self.assertIsInstance(summary.message, pb.MeshSummary)
                self.assertEqual(summary.name, "async")
                listed = await client.list_meshes()
                self.assertIn(summary.mesh_id, [mesh.mesh_id for mesh in listed])
                info = await client.info(summary.mesh_id, geometry=True)
                self.assertEqual(info.rest_positions.shape, (summary.vertex_count, 3))
                self.assertEqual(info.triangles.shape, (summary.triangle_count, 3))
                await client.unload(summary.mesh_id)
                with self.assertRaises(DeformError) as raised:
                    await client.info(summary.mesh_id)
                self.assertEqual(raised.exception.code_name, "NOT_FOUND")
                with self.assertRaises(DeformError) as raised:
                    await client.stream(summary.mesh_id)
                self.assertEqual(raised.exception.code_name, "NOT_FOUND")
                with self.assertRaises(DeformError) as raised:
                    await client.load_phantom(20000, timeout=0.05)
                self.assertEqual(raised.exception.code_name, "DEADLINE_EXCEEDED")
                with self.assertRaises(ValueError):
                    await client.stream(summary.mesh_id, encoding="jpeg")
        self.run_async(session())

    def test_frames_equal_the_blocking_clients_in_every_encoding(self):
        with DeformClient(self.server.target) as blocking:
            summary = blocking.load_phantom(1200)
        for encoding in ("float32", "quantized", "predicted"):
            expected = blocking_frames(self.server.target, summary.mesh_id, encoding)

            async def session():
                async with AsyncDeformClient(self.server.target) as client:
                    stream = await client.stream(summary.mesh_id, encoding=encoding)
                    async with stream:  # one pose at a time: a newer pose supersedes
                        sequences = [await stream.send_pose(POSES[0])]
                        frames = []
                        async for frame in stream:
                            self.assertIsInstance(frame, Frame)
                            self.assertEqual(frame.encoding, encoding)
                            frames.append(frame)
                            if len(frames) == len(POSES):
                                break
                            sequences.append(await stream.send_pose(POSES[len(frames)]))
                    self.assertEqual([frame.sequence for frame in frames], sequences)
                    return [frame.positions for frame in frames]
            with self.subTest(encoding=encoding):
                got = self.run_async(session())
                self.assertEqual(len(got), len(expected))
                for positions, reference in zip(got, expected):
                    np.testing.assert_allclose(positions, reference, rtol=0, atol=1e-6)
        with DeformClient(self.server.target) as blocking:
            blocking.unload(summary.mesh_id)

    def test_two_streams_at_once_and_a_notice(self):
        async def one(client, mesh_id, degrees):
            async with await client.stream(mesh_id) as stream:
                rejected = await stream.send_pose("nosuchjoint:x:10")
                notice = await stream.next_event(timeout=30)
                self.assertEqual(notice.kind, pb.Notice.KIND_POSE_REJECTED)
                self.assertEqual(notice.sequence, rejected)
                frames = []
                for value in degrees:
                    sent = await stream.send_pose(f"knee:flexion:{value}")
                    frame = await stream.next_frame(timeout=30)
                    self.assertEqual(frame.sequence, sent)
                    frames.append(frame.positions)
            with self.assertRaises(RuntimeError):
                await stream.send_pose("knee:flexion:10")
            self.assertEqual(len(stream.notices), 1)
            return frames

        async def session():
            async with AsyncDeformClient(self.server.target) as client:
                summary = await client.load_phantom(700)
                first, second = await asyncio.gather(one(client, summary.mesh_id, [20, 60]),
                                                     one(client, summary.mesh_id, [60, 20]))
                await client.unload(summary.mesh_id)
                return first, second
        first, second = self.run_async(session())
        # The solve's threads may order sums differently from one stream to the other (1e-18).
        np.testing.assert_allclose(first[0], second[1], rtol=0, atol=1e-6)
        np.testing.assert_allclose(first[1], second[0], rtol=0, atol=1e-6)
        self.assertGreater(float(np.abs(first[0] - first[1]).max()), 0.1)

    def test_a_stream_past_its_deadline(self):
        async def session():
            async with AsyncDeformClient(self.server.target) as client:
                summary = await client.load_phantom(500)
                stream = await client.stream(summary.mesh_id, timeout=1.0)
                await stream.send_pose("knee:flexion:30")
                self.assertEqual((await stream.next_frame(timeout=30)).sequence, 1)
                with self.assertRaises(TimeoutError):
                    await stream.next_frame(timeout=0.05)  # a local wait, the call goes on
                with self.assertRaises(DeformError) as raised:
                    await stream.next_frame(timeout=30)
                self.assertEqual(raised.exception.code_name, "DEADLINE_EXCEEDED")
                await client.unload(summary.mesh_id)
        self.run_async(session())


if __name__ == "__main__":
    unittest.main()
