"""Reading the binary little-endian PLY files of the tests: deform_client's (float32 positions)
and deformd's own writer's (double positions), both with uchar-count int32 triangle lists.
read_ply(path) -> (positions (V, 3) float64, triangles (T, 3) int64); ValueError naming what is
wrong with a file that is not such a PLY."""

import numpy as np

_TYPES = {"float": "<f4", "double": "<f8"}


def read_ply(path):
    data = open(path, "rb").read()
    end = data.find(b"end_header\n")
    if not data.startswith(b"ply\n") or end < 0:
        raise ValueError(f"{path}: not a PLY file")
    header = data[:end].decode("ascii").splitlines()
    if "format binary_little_endian 1.0" not in header:
        raise ValueError(f"{path}: not binary little-endian")
    vertices = faces = None
    coordinate_types = []
    for line in header:
        fields = line.split()
        if fields[:2] == ["element", "vertex"]:
            vertices = int(fields[2])
        elif fields[:2] == ["element", "face"]:
            faces = int(fields[2])
        elif fields[:1] == ["property"] and fields[1] in _TYPES and faces is None:
            coordinate_types.append((fields[2], _TYPES[fields[1]]))
        elif fields[:1] == ["property"] and fields[1] == "list":
            if fields[2:4] != ["uchar", "int"]:
                raise ValueError(f"{path}: face lists of {fields[2:4]}")
    if vertices is None or faces is None or [name for name, _ in coordinate_types] != \
            ["x", "y", "z"]:
        raise ValueError(f"{path}: no x, y, z vertices and faces")
    body = data[end + len(b"end_header\n"):]
    vertex_type = np.dtype(coordinate_types)
    face_type = np.dtype([("count", "u1"), ("indices", "<i4", (3,))])
    expected = vertices * vertex_type.itemsize + faces * face_type.itemsize
    if len(body) != expected:
        raise ValueError(f"{path}: {len(body)} bytes of data, the header announces {expected}")
    points = np.frombuffer(body, dtype=vertex_type, count=vertices)
    triangles = np.frombuffer(body, dtype=face_type, count=faces, offset=vertices *
                              vertex_type.itemsize)
    if faces and not np.all(triangles["count"] == 3):
        raise ValueError(f"{path}: a face that is not a triangle")
    positions = np.stack([points["x"], points["y"], points["z"]], axis=1).astype(np.float64)
    return positions, triangles["indices"].astype(np.int64)
