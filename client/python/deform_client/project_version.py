"""Reads deformd's version, `project(deformd VERSION X.Y.Z)` in the repository's top-level
CMakeLists.txt: the one source of truth (the C++ programs print it with --version). Imports
nothing of the package, so that setup.py loads this file alone."""

import pathlib
import re

_PROJECT = re.compile(r"project\(\s*deformd\s+VERSION\s+([0-9]+(?:\.[0-9]+)*)")


def read_project_version(cmakelists: pathlib.Path) -> str:
    """The VERSION of `project(deformd ...)` in a CMakeLists.txt; RuntimeError without one."""
    match = _PROJECT.search(pathlib.Path(cmakelists).read_text())
    if not match:
        raise RuntimeError(f"{cmakelists} has no project(deformd VERSION X.Y.Z)")
    return match.group(1)
