#!/usr/bin/env python3
"""Loads the built-in knee phantom into a running deformd, bends its knee and writes the deformed
mesh as a PLY (the triangles come once from GetMeshInfo, the positions from one frame).

    python3 client/python/examples/bend_knee.py --target 127.0.0.1:50051 --out bent_knee.ply

TLS and the bearer token come from the environment, as for the command-line clients
(DEFORM_TLS=1, DEFORM_TLS_CA, DEFORM_TLS_CERT, DEFORM_TLS_KEY, DEFORM_TLS_SERVER_NAME,
DEFORM_TOKEN). Prints one line per load stage, then one line describing the frame. Exits 1 with
the reason on stderr when a call fails. The phantom is unloaded at the end unless --keep-mesh.
"""

import argparse
import pathlib
import sys

try:  # the installed package, else the one beside this directory
    import deform_client  # noqa: F401
except ImportError:
    sys.path.insert(0, str(pathlib.Path(__file__).resolve().parents[1]))

from deform_client import DeformError, client_from_environment  # noqa: E402
from deform_client.mesh_files import write_ply  # noqa: E402


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--target", default=None,
                        help="deformd's host:port (default: DEFORM_TARGET or 127.0.0.1:50051)")
    parser.add_argument("--vertices", type=int, default=2000, help="phantom size (default 2000)")
    parser.add_argument("--degrees", type=float, default=90.0, help="knee flexion (default 90)")
    parser.add_argument("--encoding", default="predicted",
                        choices=["float32", "quantized", "predicted"])
    parser.add_argument("--out", default="bent_knee.ply", help="PLY to write")
    parser.add_argument("--keep-mesh", action="store_true", help="leave the phantom loaded")
    args = parser.parse_args()

    client = client_from_environment(args.target)
    try:
        mesh = client.load_phantom(
            args.vertices, name="bend_knee",
            progress=lambda stage, ms: print(f"load: {stage} after {ms:.1f} ms"))
        try:
            info = client.info(mesh.mesh_id, geometry=True)
            with client.stream(mesh.mesh_id, encoding=args.encoding) as stream:
                stream.send_pose({"joint": "knee", "axis": "flexion", "degrees": args.degrees})
                frame = stream.next_frame(timeout=60)
            if frame is None:
                raise DeformError("INTERNAL", "the stream ended without a frame")
            write_ply(args.out, frame.positions, info.triangles)
        finally:
            if not args.keep_mesh:
                client.unload(mesh.mesh_id)
    except (DeformError, TimeoutError, OSError) as error:
        print(f"bend_knee: {error}", file=sys.stderr)
        return 1
    finally:
        client.close()
    print(f"wrote {args.out}: {len(frame.positions)} vertices, {len(info.triangles)} triangles, "
          f"knee flexion {args.degrees:g} degrees, {frame.encoding} frame of {frame.wire_bytes} "
          f"bytes (largest error {frame.max_error:.3g}), decoded in {frame.decode_ms:.2f} ms")
    return 0


if __name__ == "__main__":
    sys.exit(main())
