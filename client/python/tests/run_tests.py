"""Runs the Python client's tests (unittest) and fails loudly: a module that does not import, no
test run at all, or any skipped test is a failure, never a silent pass.

    python3 client/python/tests/run_tests.py [test_basics test_encodings ...]   # default: all

Tests the package in client/python (put first on sys.path, and on PYTHONPATH for the examples the
tests run), or with --installed the deform_client this interpreter has installed, which must not
come from the source tree (test_installed_package.py runs the suite that way in a fresh venv).
ctest runs one module per test (client/python/CMakeLists.txt) with DEFORM_TEST_DEFORMD and
DEFORM_TEST_DEFORM_VR pointing into the build.
"""

import os
import pathlib
import sys
import unittest

HERE = pathlib.Path(__file__).resolve().parent
SOURCE = HERE.parent  # holds the deform_client of the source tree


def use_source_package():
    sys.path.insert(0, str(SOURCE))
    os.environ["PYTHONPATH"] = os.pathsep.join(
        [str(SOURCE)] + [p for p in os.environ.get("PYTHONPATH", "").split(os.pathsep) if p])


def check_installed_package():
    """The installed deform_client, not the source tree's; RuntimeError otherwise."""
    sys.path[:] = [p for p in sys.path if pathlib.Path(p or ".").resolve() != SOURCE]
    import deform_client
    location = pathlib.Path(deform_client.__file__).resolve()
    if SOURCE in location.parents:
        raise RuntimeError(f"deform_client comes from the source tree ({location})")
    print(f"run_tests: deform_client {deform_client.__version__} from {location.parent}")


def main(arguments):
    names = [name for name in arguments if name != "--installed"]
    if "--installed" in arguments:
        check_installed_package()
    else:
        use_source_package()
    sys.path.insert(0, str(HERE))
    names = names or sorted(path.stem for path in HERE.glob("test_*.py")
                            if path.stem != "test_installed_package")
    suite = unittest.defaultTestLoader.loadTestsFromNames(names)
    result = unittest.TextTestRunner(verbosity=2).run(suite)
    if result.testsRun == 0:
        print("run_tests: no test ran", file=sys.stderr)
        return 1
    if result.skipped:
        print(f"run_tests: {len(result.skipped)} skipped tests count as failures",
              file=sys.stderr)
        return 1
    return 0 if result.wasSuccessful() else 1


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
