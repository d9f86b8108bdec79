"""meshoptimizer's vertex decoder through ctypes, from Debian's shared library.

Contract: decode_vertex_buffer(data, destination) fills `destination` (a writable, C-contiguous
numpy array of shape (vertex_count, k): one record of destination.itemsize * k bytes per vertex)
with what meshopt_encodeVertexBuffer encoded; ValueError when the bytes do not decode to that many
vertices. The library is Debian's libmeshoptimizer2d (soname libmeshoptimizer.so.2d, meshoptimizer
0.18); DEFORM_MESHOPTIMIZER_LIB names another file. Loaded once, on first use; OSError naming what
was tried when no library loads. Thread safety: the decoder keeps no state, so any number of
threads may call it.
"""

from __future__ import annotations

import ctypes
import ctypes.util
import os
import threading
from typing import List, Optional

import numpy as np

_LIBRARY_NAMES = ("libmeshoptimizer.so.2d", "libmeshoptimizer.so")
_library: Optional[ctypes.CDLL] = None
_library_lock = threading.Lock()


def _load_library() -> ctypes.CDLL:
    tried: List[str] = []
    override = os.environ.get("DEFORM_MESHOPTIMIZER_LIB")
    names = [override] if override else list(_LIBRARY_NAMES)
    if not override:
        found = ctypes.util.find_library("meshoptimizer")
        if found:
            names.append(found)
    for name in names:
        try:
            library = ctypes.CDLL(name)
        except OSError as error:
            tried.append(f"{name}: {error}")
            continue
        decode = library.meshopt_decodeVertexBuffer
        decode.argtypes = [ctypes.c_void_p, ctypes.c_size_t, ctypes.c_size_t, ctypes.c_char_p,
                           ctypes.c_size_t]
        decode.restype = ctypes.c_int
        return library
    raise OSError("cannot load meshoptimizer's shared library (Debian package libmeshoptimizer2d; "
                  "or set DEFORM_MESHOPTIMIZER_LIB): " + "; ".join(tried))


def library() -> ctypes.CDLL:
    """The loaded library (loads it on first call)."""
    global _library
    with _library_lock:
        if _library is None:
            _library = _load_library()
        return _library


def decode_vertex_buffer(data: bytes, destination: np.ndarray) -> None:
    """Decodes meshopt_encodeVertexBuffer's bytes into `destination` (shape (vertices, k))."""
    if destination.ndim != 2 or not destination.flags.c_contiguous or \
            not destination.flags.writeable:
        raise ValueError("destination must be a writable, C-contiguous 2-D array")
    vertex_count = destination.shape[0]
    vertex_size = destination.shape[1] * destination.itemsize
    result = library().meshopt_decodeVertexBuffer(destination.ctypes.data, vertex_count,
                                                  vertex_size, bytes(data), len(data))
    if result != 0:
        raise ValueError(f"encoded frame's bytes do not decode to {vertex_count} vertices "
                         f"(meshopt_decodeVertexBuffer returned {result})")
