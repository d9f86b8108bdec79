"""Runs the Python client's tests (unittest) and fails loudly: a module that does not import, no
test run at all, or any skipped test is a failure, never a silent pass.

    python3 client/python/tests/run_tests.py [test_basics test_encodings ...]   # default: all

ctest runs one module per test (client/python/CMakeLists.txt) with DEFORM_PYTHON_STUBS and
DEFORM_TEST_DEFORMD pointing into the build.
"""

import pathlib
import sys
import unittest

HERE = pathlib.Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent))  # deform_client
sys.path.insert(0, str(HERE))


def main(names):
    names = names or sorted(path.stem for path in HERE.glob("test_*.py"))
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
