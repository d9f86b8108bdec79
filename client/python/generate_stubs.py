#!/usr/bin/env python3
"""Generates the deform.v1 stubs that the package ships (deform_client/_proto/), or checks them.

    python3 client/python/generate_stubs.py          # rewrites deform_client/_proto/*_pb2*
    python3 client/python/generate_stubs.py --check  # exit 1 naming every file that differs

The stubs are committed so that `pip install client/python` needs neither protoc nor the C++
build. They are what Debian's protoc (the one the C++ build uses, which matches the
python3-protobuf runtime) and grpc_python_plugin make of proto/deform/v1/deform.proto
(deform_pb2.py, its type stubs deform_pb2.pyi, deform_pb2_grpc.py), with two rewrites so that
they live inside the package instead of as a top-level `deform` package: deform_pb2_grpc.py
imports deform_pb2 relatively, and the messages' module is deform_client._proto.deform_pb2.
The descriptor keeps its file name deform/v1/deform.proto. ctest's python_client_stubs_current
runs --check, so a proto change without regenerated stubs fails the tests.

Beside them, google.rpc.Status and its error details (rpc_status_pb2*, rpc_error_details_pb2*:
what the server's RetryInfo is read from) are made from Debian's golang-github-gogo-googleapis-dev
protos (the ones the C++ build uses; GOOGLE_RPC_PROTO_DIR names another copy of their
google/rpc/), with their proto package renamed deform_client.rpc and their files placed as
deform_client/_proto/rpc_*.proto: the same wire format under names of this package's own, so
that they never collide in protobuf's descriptor pool with the real google.rpc modules
(googleapis-common-protos) an application may import too. Any's type URLs still name
google.rpc.RetryInfo, which is what the client compares.

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
GOOGLE_RPC_DIR = pathlib.Path(os.environ.get(
    "GOOGLE_RPC_PROTO_DIR", "/usr/share/gocode/src/github.com/gogo/googleapis/google/rpc"))
GOOGLE_RPC = ("status", "error_details")
RPC_PACKAGE = ("package google.rpc;", "package deform_client.rpc;")
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
    texts.update(generate_google_rpc(protoc))
    for name, before, after in REWRITES:
        if texts[name].count(before) != 1:
            sys.exit(f"generate_stubs: {name} holds {before!r} "
                     f"{texts[name].count(before)} times, not once (a new protoc?)")
        texts[name] = texts[name].replace(before, after)
    for name, text in texts.items():
        (pathlib.Path(directory) / name).write_text(text)
    return texts


def generate_google_rpc(protoc):
    """{file name: text} of rpc_status_pb2.py(i) and rpc_error_details_pb2.py(i)."""
    texts = {}
    with tempfile.TemporaryDirectory() as work:
        tree = pathlib.Path(work) / "in" / "deform_client" / "_proto"
        tree.mkdir(parents=True)
        out = pathlib.Path(work) / "out"
        out.mkdir()
        for name in GOOGLE_RPC:
            source = GOOGLE_RPC_DIR / f"{name}.proto"
            if not source.is_file():
                sys.exit(f"generate_stubs: {source} not found (Debian's "
                         f"golang-github-gogo-googleapis-dev; or set GOOGLE_RPC_PROTO_DIR)")
            text = source.read_text()
            if text.count(RPC_PACKAGE[0]) != 1:
                sys.exit(f"generate_stubs: {source} does not declare {RPC_PACKAGE[0]!r} once")
            (tree / f"rpc_{name}.proto").write_text(text.replace(*RPC_PACKAGE))
        subprocess.run([protoc, f"-I{pathlib.Path(work) / 'in'}", f"--python_out={out}",
                        f"--pyi_out={out}"]
                       + [str(tree / f"rpc_{name}.proto") for name in GOOGLE_RPC], check=True)
        for name in GOOGLE_RPC:
            for suffix in (".py", ".pyi"):
                file_name = f"rpc_{name}_pb2{suffix}"
                texts[file_name] = (out / "deform_client" / "_proto" / file_name).read_text()
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
        print(f"generate_stubs: {', '.join(stale)} differ from what {PROTO} and google/rpc "
              f"generate; run python3 client/python/generate_stubs.py", file=sys.stderr)
        return 1
    print(f"generate_stubs: {len(texts)} stubs match {PROTO} and google/rpc")
    return 0


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--check", action="store_true",
                        help="compare instead of writing; exit 1 when a stub differs")
    if parser.parse_args().check:
        return check()
    PACKAGE_DIR.mkdir(exist_ok=True)
    print(f"generate_stubs: wrote {', '.join(sorted(generate(PACKAGE_DIR)))} into {PACKAGE_DIR}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
