"""The package as a user installs it: a fresh venv over Debian's python3-grpcio, python3-protobuf
and python3-numpy (--system-site-packages), `pip install --no-build-isolation --no-index
client/python` into it (offline: nothing comes from a package index), then the whole test suite
(run_tests.py --installed) from that venv's interpreter, in a directory outside the source tree,
against a real deformd; deform_client must come from the venv, with deformd's version, its
stubs, py.typed and the type stubs of the messages installed."""

import os
import pathlib
import subprocess
import sys
import tempfile
import unittest

HERE = pathlib.Path(__file__).resolve().parent
SOURCE = HERE.parent
sys.path.insert(0, str(SOURCE))
from deform_client.project_version import read_project_version  # noqa: E402


def run(command, cwd):
    """`command` without PYTHONPATH (run_tests.py puts the source tree on it)."""
    environment = {key: value for key, value in os.environ.items() if key != "PYTHONPATH"}
    return subprocess.run([str(part) for part in command], capture_output=True, text=True,
                          timeout=900, cwd=cwd, env=environment)


class InstalledPackageTest(unittest.TestCase):
    def test_the_suite_passes_against_the_installed_package(self):
        version = read_project_version(SOURCE.parents[1] / "CMakeLists.txt")
        with tempfile.TemporaryDirectory(prefix="deform-client-venv-") as directory:
            venv = pathlib.Path(directory) / "venv"
            made = run([sys.executable, "-m", "venv", "--system-site-packages", venv],
                       cwd=directory)
            self.assertEqual(made.returncode, 0, made.stderr)
            python = venv / "bin" / "python"
            # Without an index pip fails unless the system site has grpcio, protobuf and numpy.
            installed = run([python, "-m", "pip", "install", "--no-build-isolation",
                             "--no-index", SOURCE], cwd=directory)
            self.assertEqual(installed.returncode, 0, installed.stdout + installed.stderr)
            self.assertIn(f"Successfully installed deform-client-{version}", installed.stdout)

            probe = run([python, "-c", "import deform_client, pathlib; "
                         "p = pathlib.Path(deform_client.__file__).parent; "
                         "print(deform_client.__version__); print(p); "
                         "print((p / 'py.typed').is_file(), "
                         "(p / '_proto' / 'deform_pb2.pyi').is_file()); "
                         "print(deform_client.pb.MeshSummary.__module__)"], cwd=directory)
            self.assertEqual(probe.returncode, 0, probe.stderr)
            printed_version, location, markers, module = probe.stdout.split("\n")[:4]
            self.assertEqual(printed_version, version)
            self.assertTrue(pathlib.Path(location).is_relative_to(venv), location)
            self.assertEqual(markers, "True True")
            self.assertEqual(module, "deform_client._proto.deform_pb2")

            suite = run([python, HERE / "run_tests.py", "--installed"], cwd=directory)
            sys.stderr.write(suite.stderr[-4000:])
            self.assertEqual(suite.returncode, 0, suite.stdout + suite.stderr[-20000:])
            self.assertIn(f"run_tests: deform_client {version} from {venv}", suite.stdout)
            self.assertRegex(suite.stderr, r"\nRan [1-9][0-9]+ tests in ")


if __name__ == "__main__":
    unittest.main()
