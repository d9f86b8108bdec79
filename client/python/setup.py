"""Builds the deform-client package (the metadata is in pyproject.toml).

The version is deformd's, read from the repository's top-level CMakeLists.txt
(deform_client/project_version.py) and written into the built package as _installed_version.py;
an sdist keeps it in its PKG-INFO. Build from the source tree: pip install client/python.
"""

import importlib.util
import pathlib
import re

from setuptools import setup
from setuptools.command.build_py import build_py

HERE = pathlib.Path(__file__).resolve().parent


def project_version():
    cmakelists = HERE.parents[1] / "CMakeLists.txt"
    if cmakelists.is_file():
        # The package's own reader, loaded alone (importing the package needs grpc and numpy).
        spec = importlib.util.spec_from_file_location(
            "deform_project_version", HERE / "deform_client" / "project_version.py")
        module = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(module)
        return module.read_project_version(cmakelists)
    pkg_info = HERE / "PKG-INFO"  # an unpacked sdist
    if pkg_info.is_file():
        match = re.search(r"^Version: (\S+)$", pkg_info.read_text(), re.MULTILINE)
        if match:
            return match.group(1)
    raise RuntimeError(f"no {cmakelists} (build from the deformd repository) and no PKG-INFO")


VERSION = project_version()


class BuildPyWithVersion(build_py):
    def run(self):
        super().run()
        target = pathlib.Path(self.build_lib) / "deform_client" / "_installed_version.py"
        target.write_text(f'"""Written by setup.py."""\n\nVERSION = "{VERSION}"\n')


setup(version=VERSION, packages=["deform_client", "deform_client._proto"],
      package_data={"deform_client": ["py.typed"], "deform_client._proto": ["*.pyi"]},
      cmdclass={"build_py": BuildPyWithVersion})
