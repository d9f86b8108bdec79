#!/usr/bin/env python3
"""Generates the deform.v1 stubs that the package ships (deform_client/_proto/), or checks them.

    python3 client/python/generate_stubs.py          # rewrites deform_client/_proto/deform_pb2*
    python3 client/python/generate_stubs.py --check  # exit 1 naming every file that differs

The stubs are committed so that `pip install client/python` needs neither protoc nor the C++
build. They are what Debian's protoc (the one the C++ build uses, which matches the
python3-protobuf runtime) and grpc_python_plugin make of proto/deform/v1/deform.proto
(deform_pb2.py, its type stubs deform_pb2.pyi, deform_pb2_grpc.py), with two rewrites so that
they live inside the package instead of as a top-level `deform` package: deform_pb2_grpc.py
imports deform_pb2 relatively, and the messages' module is deform_client._proto.deform_pb2.
The descriptor keeps its file name deform/v1/deform.proto. ctest's python_client_stubs_current
runs --check, so a proto change without regenerated stubs fails the tests.

PROTOC and GRPC_PYTHON_PLUGIN name other programs; exit 2 when one is missing.
"""

import argparse
import difflib
import os
import pathlib
import shutil
import subprocess
import sys
import tempfile

HERE = pathlib.Path(__file__).resolve().parent
PROTO_ROOT = HERE.parents[1] / "proto"
PROTO = "deform/v1/deform.proto"
PACKAGE_DIR = HERE / "deform_client" / "_proto"
MODULE = "deform_client._proto.deform_pb2"
GENERATED = ("deform_pb2.py", "deform_pb2.pyi", "deform_pb2_grpc.py")
# (file, text protoc writes, text the package ships): each must occur exactly once.
REWRITES = (
    ("deform_pb2.py", "'deform.v1.deform_pb2'", f"'{MODULE}'"),
    ("deform_pb2_grpc.py", "from deform.v1 import deform_pb2 as",
     "from . import deform_pb2 as"),
)


def program(variable, name):
    found = os.environ.get(variable) or shutil.which(name)
    if not found:
        sys.exit(f"generate_stubs: {name} not found (Debian's protobuf-compiler and "
                 f"protobuf-compiler-grpc; or set {variable})")
    return found


def generate(directory):
    """Writes the shipped form of the stubs into `directory`; returns {file name: text}."""
    protoc = program("PROTOC", "protoc")
    plugin = program("GRPC_PYTHON_PLUGIN", "grpc_python_plugin")
    with tempfile.TemporaryDirectory() as out:
        subprocess.run([protoc, f"-I{PROTO_ROOT}", f"--python_out={out}", f"--pyi_out={out}",
                        f"--grpc_python_out={out}", f"--plugin=protoc-gen-grpc_python={plugin}",
                        str(PROTO_ROOT / PROTO)], check=True)
        texts = {name: (pathlib.Path(out) / "deform" / "v1" / name).read_text()
                 for name in GENERATED}
    for name, before, after in REWRITES:
        if texts[name].count(before) != 1:
            sys.exit(f"generate_stubs: {name} holds {before!r} "
                     f"{texts[name].count(before)} times, not once (a new protoc?)")
        texts[name] = texts[name].replace(before, after)
    for name, text in texts.items():
        (pathlib.Path(directory) / name).write_text(text)
    return texts


def check():
    with tempfile.TemporaryDirectory() as directory:
        texts = generate(directory)
    stale = []
    for name, text in texts.items():
        shipped_path = PACKAGE_DIR / name
        shipped = shipped_path.read_text() if shipped_path.is_file() else ""
        if shipped != text:
            stale.append(name)
            sys.stdout.writelines(list(difflib.unified_diff(
                shipped.splitlines(True), text.splitlines(True), f"shipped/{name}",
                f"generated/{name}", n=1))[:40])
    if stale:
        print(f"generate_stubs: {', '.join(stale)} differ from what {PROTO} generates; run "
              f"python3 client/python/generate_stubs.py", file=sys.stderr)
        return 1
    print(f"generate_stubs: {len(texts)} stubs match {PROTO}")
    return 0


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--check", action="store_true",
                        help="compare instead of writing; exit 1 when a stub differs")
    if parser.parse_args().check:
        return check()
    PACKAGE_DIR.mkdir(exist_ok=True)
    generate(PACKAGE_DIR)
    print(f"generate_stubs: wrote {', '.join(GENERATED)} into {PACKAGE_DIR}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
