#!/usr/bin/env python3
"""Measures the Python client's decoding per frame encoding: streams a flexion trajectory (0 to
--max-degrees in --frames poses, one pose at a time, each frame awaited) in float32, quantized and
predicted, and prints per encoding the bytes per vertex that travelled and the decode time per
frame (median and 90th percentile of the client's own timing, Frame.decode_ms).

    python3 client/python/examples/measure_decode.py --target 127.0.0.1:50051        # phantom
    python3 client/python/examples/measure_decode.py --target 127.0.0.1:50051 \\
        --mesh ../shared/data/leg/leg_25969.obj --skeleton ../shared/data/leg/leg.tgf \\
        --joint 1 --axis x

TLS and the token come from the environment (see bend_knee.py). The mesh is unloaded at the end.
"""

import argparse
import pathlib
import statistics
import sys

try:  # the installed package, else the one beside this directory
    import deform_client  # noqa: F401
except ImportError:
    sys.path.insert(0, str(pathlib.Path(__file__).resolve().parents[1]))

from deform_client import DeformError, client_from_environment  # noqa: E402


def percentile(values, fraction):
    ordered = sorted(values)
    return ordered[min(len(ordered) - 1, int(fraction * len(ordered)))]


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--target", default=None)
    parser.add_argument("--mesh", help="mesh file to upload (default: the phantom)")
    parser.add_argument("--skeleton", help="its skeleton (.tgf or JSON)")
    parser.add_argument("--vertices", type=int, default=2000, help="phantom size")
    parser.add_argument("--joint", default="knee")
    parser.add_argument("--axis", default="flexion")
    parser.add_argument("--max-degrees", type=float, default=120.0)
    parser.add_argument("--frames", type=int, default=48)
    args = parser.parse_args()

    client = client_from_environment(args.target)
    try:
        if args.mesh:
            mesh = client.load_files(args.mesh, args.skeleton)
        else:
            mesh = client.load_phantom(args.vertices)
        print(f"{mesh.name}: {mesh.vertex_count} vertices, {args.frames} frames, "
              f"{args.joint}:{args.axis} 0 to {args.max_degrees:g} degrees")
        try:
            for encoding in ("float32", "quantized", "predicted"):
                decode_ms, wire_bytes, encodings = [], [], set()
                with client.stream(mesh.mesh_id, encoding=encoding) as stream:
                    for k in range(args.frames):
                        degrees = args.max_degrees * k / max(1, args.frames - 1)
                        stream.send_pose(f"{args.joint}:{args.axis}:{degrees}")
                        frame = stream.next_frame(timeout=120)
                        decode_ms.append(frame.decode_ms)
                        wire_bytes.append(frame.wire_bytes)
                        encodings.add(frame.encoding)
                print(f"{encoding:>9}: {statistics.mean(wire_bytes) / mesh.vertex_count:6.3f} "
                      f"bytes/vertex, decode median {statistics.median(decode_ms):.3f} ms, "
                      f"p90 {percentile(decode_ms, 0.9):.3f} ms (frames sent as "
                      f"{', '.join(sorted(encodings))})")
        finally:
            client.unload(mesh.mesh_id)
    except (DeformError, TimeoutError, OSError) as error:
        print(f"measure_decode: {error}", file=sys.stderr)
        return 1
    finally:
        client.close()
    return 0


if __name__ == "__main__":
    sys.exit(main())
