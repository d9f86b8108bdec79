"""Writing a deformed frame as a mesh file, with the triangles GetMeshInfo sent once.

write_ply(path, positions, triangles): binary little-endian PLY ("vertex" x, y, z float32;
"face" vertex_indices as uchar count + 3 int32). positions (V, 3), triangles (T, 3) with indices
< V; ValueError otherwise. Readable by deformd's own PLY reader, MeshLab, Blender, three.js.
"""

from __future__ import annotations

import os
from typing import Union

import numpy as np


def write_ply(path: Union[str, os.PathLike], positions: np.ndarray,
              triangles: np.ndarray) -> None:
    positions = np.ascontiguousarray(positions, dtype="<f4")
    triangles = np.asarray(triangles)
    if positions.ndim != 2 or positions.shape[1] != 3:
        raise ValueError(f"positions must have shape (V, 3), not {positions.shape}")
    if triangles.ndim != 2 or triangles.shape[1] != 3:
        raise ValueError(f"triangles must have shape (T, 3), not {triangles.shape}")
    if triangles.size and (triangles.min() < 0 or triangles.max() >= len(positions)):
        raise ValueError("a triangle names a vertex out of range")
    faces = np.empty(len(triangles), dtype=[("count", "u1"), ("indices", "<i4", (3,))])
    faces["count"] = 3
    faces["indices"] = triangles
    header = ("ply\nformat binary_little_endian 1.0\ncomment written by deform_client\n"
              f"element vertex {len(positions)}\n"
              "property float x\nproperty float y\nproperty float z\n"
              f"element face {len(triangles)}\n"
              "property list uchar int vertex_indices\nend_header\n")
    with open(path, "wb") as out:
        out.write(header.encode("ascii"))
        out.write(positions.tobytes())
        out.write(faces.tobytes())
