"""examples/bend_knee.py against a real deformd: it loads the phantom, bends the knee to 90
degrees and writes a valid PLY (header, counts, finite positions, triangles in range), which
deformd itself reads back as an upload, with the shin swung backwards; a failing call exits 1
with the reason."""

import pathlib
import subprocess
import sys
import tempfile
import unittest

import numpy as np

from deform_client import DeformClient
from deformd_process import DeformdProcess
from ply_files import read_ply
from mesh_writers import write_skeleton_json

EXAMPLE = pathlib.Path(__file__).resolve().parents[1] / "examples" / "bend_knee.py"


def run_example(*args):
    return subprocess.run([sys.executable, str(EXAMPLE), *args], capture_output=True, text=True,
                          timeout=120)


class ExampleTest(unittest.TestCase):
    def test_bend_knee_writes_a_valid_ply_of_the_bent_phantom(self):
        with DeformdProcess("--workers", "2") as server, \
                tempfile.TemporaryDirectory() as directory:
            out = pathlib.Path(directory) / "bent.ply"
            done = run_example("--target", server.target, "--vertices", "1500", "--out",
                               str(out))
            self.assertEqual(done.returncode, 0, done.stderr)
            self.assertIn("load: READY", done.stdout)
            self.assertIn(f"wrote {out}", done.stdout)
            positions, triangles = read_ply(out)

            client = DeformClient(server.target)
            self.assertEqual(client.list_meshes(), [])  # the example unloaded its phantom
            rest_mesh = client.load_phantom(1500)
            rest = client.info(rest_mesh.mesh_id, geometry=True)
            self.assertEqual(positions.shape, rest.rest_positions.shape)
            np.testing.assert_array_equal(triangles, rest.triangles)
            self.assertTrue(np.all(np.isfinite(positions)))
            # Flexion swings the shin backwards (-Z): the foot, 4 units below the knee at rest,
            # ends about 4 units behind it.
            foot = int(np.argmin(rest.rest_positions[:, 1]))
            self.assertLess(positions[foot, 2], rest.rest_positions[foot, 2] - 3.0)
            self.assertGreater(positions[foot, 1], rest.rest_positions[foot, 1] + 3.0)
            # deformd reads the file back (its own PLY reader) with the phantom's skeleton.
            skeleton = pathlib.Path(directory) / "phantom.json"
            write_skeleton_json(skeleton, rest_mesh)
            uploaded = client.load_files(out, skeleton)
            self.assertEqual(uploaded.vertex_count, rest_mesh.vertex_count)
            self.assertEqual(uploaded.triangle_count, rest_mesh.triangle_count)
            client.close()

    def test_a_failing_call_exits_1_with_the_reason(self):
        with DeformdProcess("--workers", "1", "--max-vertices", "100") as server, \
                tempfile.TemporaryDirectory() as directory:
            done = run_example("--target", server.target, "--out",
                               str(pathlib.Path(directory) / "bent.ply"))
            self.assertEqual(done.returncode, 1)
            self.assertIn("bend_knee: RESOURCE_EXHAUSTED", done.stderr)


if __name__ == "__main__":
    unittest.main()
