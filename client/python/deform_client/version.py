"""The package's version (`deform_client.__version__`): deformd's own (project_version.py).

An installed package carries it in _installed_version.py, written by setup.py when the package is
built; run from the source tree (PYTHONPATH=client/python) it is read from the repository's
CMakeLists.txt. RuntimeError when neither is there.
"""

import pathlib

from .project_version import read_project_version


def _version() -> str:
    try:
        from ._installed_version import VERSION  # type: ignore[import]
    except ImportError:
        cmakelists = pathlib.Path(__file__).resolve().parents[3] / "CMakeLists.txt"
        if not cmakelists.is_file():
            raise RuntimeError(f"deform_client: no _installed_version.py and no {cmakelists}") \
                from None
        return read_project_version(cmakelists)
    return str(VERSION)


__version__ = _version()
