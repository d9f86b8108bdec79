"""Decoders of deformd's frame encodings (proto/deform/v1/deform.proto, server/core/codec/).

Every decoder returns the frame's positions as a new numpy float32 array of shape (V, 3), in the
mesh's own vertex order, model units:

- FLOAT32: `DeformFrame.positions`, little-endian float32 x, y, z per vertex.
- QUANTIZED: meshoptimizer's vertex codec over 8-byte records (uint16 a, b, c, 0) per vertex;
  coordinate k = float32(origin[k] + a_k * step), computed in double.
- PREDICTED: the same records, zigzag-coded residuals r; coordinate k = float32(p_k + r * step),
  computed in double, where p is the four-bone linear blend skinning prediction computed in
  float32 operation by operation as the proto specifies (predict_positions). numpy's float32
  ufuncs round every operation and never fuse a multiply and an add, so the prediction is bit for
  bit the encoder's, and each decoded coordinate is within the frame's max_error (step / 2) of the
  server's solution plus the float32 rounding of the result.

Raises ValueError for a frame that does not decode (wrong size, bad bytes, a non-positive step,
the wrong number of bone transforms). Assumes a little-endian host for meshoptimizer's records (as
the C++ client does). A FrameDecoder holds one mesh's vertex count and, for PREDICTED, its rest
positions and prediction weights; it keeps no state between frames, so a skipped frame costs
nothing. Thread safety: its arrays are read-only after construction, so decode() may run from
several threads at once.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Optional, Union

import numpy as np

from . import meshopt

if TYPE_CHECKING:
    from .stubs import pb

FLOAT32 = 1
QUANTIZED = 2
PREDICTED = 3

ENCODING_NAMES = {FLOAT32: "float32", QUANTIZED: "quantized", PREDICTED: "predicted"}
BONES_PER_VERTEX = 4
FLOATS_PER_BONE_TRANSFORM = 12


def encoding_from_name(encoding: Union[str, int]) -> int:
    """'float32' | 'quantized' | 'predicted' (or the enum value) -> the FrameEncoding value."""
    if isinstance(encoding, int) and encoding in ENCODING_NAMES:
        return encoding
    for value, name in ENCODING_NAMES.items():
        if isinstance(encoding, str) and encoding.lower() == name:
            return value
    raise ValueError(f"unknown frame encoding {encoding!r} (float32, quantized or predicted)")


def decode_float32(positions: bytes, vertex_count: int) -> np.ndarray:
    """Little-endian float32 x, y, z bytes -> (V, 3) float32."""
    if len(positions) != 12 * vertex_count:
        raise ValueError(f"a float32 frame of {len(positions)} bytes; {vertex_count} vertices "
                         f"need {12 * vertex_count}")
    return np.frombuffer(positions, dtype="<f4").astype(np.float32).reshape(vertex_count, 3)


def decode_records(data: bytes, vertex_count: int) -> np.ndarray:
    """meshoptimizer's vertex codec -> (V, 4) uint16 records."""
    records = np.empty((vertex_count, 4), dtype=np.uint16)
    meshopt.decode_vertex_buffer(data, records)
    return records


def unzigzag(records: np.ndarray) -> np.ndarray:
    """uint16 zigzag codes -> int32 residuals ((a >> 1) ^ -(a & 1))."""
    codes = records.astype(np.int32)
    return (codes >> 1) ^ -(codes & 1)


def predict_positions(rest: np.ndarray, bones: np.ndarray, weights: np.ndarray,
                      transforms: np.ndarray) -> np.ndarray:
    """The proto's prediction, float32 with every operation rounded, in the proto's order.

    rest (V, 3) float32, bones (V, 4) integer, weights (V, 4) float32, transforms (B, 12)
    float32 rows [R | t] row-major. Returns (V, 3) float32.
    """
    vx, vy, vz = rest[:, 0], rest[:, 1], rest[:, 2]
    predicted = np.zeros(rest.shape, dtype=np.float32)
    for j in range(BONES_PER_VERTEX):
        m = transforms[bones[:, j]]  # (V, 12): each vertex's j-th bone transform
        w = weights[:, j]
        for r in range(3):
            s = m[:, 4 * r] * vx
            s = s + m[:, 4 * r + 1] * vy
            s = s + m[:, 4 * r + 2] * vz
            s = s + m[:, 4 * r + 3]
            predicted[:, r] = predicted[:, r] + w * s
    return predicted


class FrameDecoder:
    """Decodes one mesh's frames (any encoding) into (V, 3) float32 positions."""

    def __init__(self, vertex_count: int, rest_positions: Optional[bytes] = None,
                 prediction_weights: Optional[pb.PredictionWeights] = None):
        """vertex_count: the mesh's (MeshSummary.vertex_count). For PREDICTED frames also the
        rest positions (GetMeshInfoResponse.rest_positions bytes) and PredictionWeights message
        (GetMeshInfoRequest.include_prediction_weights); ValueError when their sizes do not match
        vertex_count or a weight names a bone out of range or is negative or not finite."""
        self.vertex_count = int(vertex_count)
        self._rest = None
        self._bones = None
        self._weights = None
        self._num_bones = 0
        if prediction_weights is None:
            return
        n = self.vertex_count
        slots = BONES_PER_VERTEX * n
        if (rest_positions is None or len(rest_positions) != 12 * n
                or len(prediction_weights.bones) != 2 * slots
                or len(prediction_weights.weights) != 4 * slots):
            raise ValueError(f"prediction weights or rest positions do not match {n} vertices")
        bones = np.frombuffer(prediction_weights.bones, dtype="<u2").reshape(n, 4)
        weights = np.frombuffer(prediction_weights.weights, dtype="<f4").reshape(n, 4)
        num_bones = int(prediction_weights.num_bones)
        if n > 0 and (int(bones.max()) >= num_bones or not np.all(np.isfinite(weights))
                      or float(weights.min()) < 0):
            raise ValueError("prediction weights name a bone out of range or are negative")
        self._rest = decode_float32(rest_positions, n)
        self._bones = bones.astype(np.intp)
        self._weights = weights.astype(np.float32)
        self._num_bones = num_bones

    @property
    def can_predict(self) -> bool:
        return self._rest is not None

    def decode(self, frame: pb.DeformFrame) -> np.ndarray:
        """A DeformFrame message -> (V, 3) float32 positions."""
        if not frame.HasField("encoded"):
            return decode_float32(frame.positions, self.vertex_count)
        return self.decode_encoded(frame.encoded)

    def decode_encoded(self, encoded: pb.EncodedPositions) -> np.ndarray:
        """An EncodedPositions message -> (V, 3) float32 positions."""
        step = encoded.step
        if not math.isfinite(step) or step <= 0:
            raise ValueError("encoded frame's step must be positive and finite")
        if encoded.encoding == QUANTIZED:
            if len(encoded.origin) != 3:
                raise ValueError("a quantized frame without its box origin")
            records = decode_records(encoded.data, self.vertex_count)
            origin = np.array(encoded.origin, dtype=np.float64)
            values = origin + records[:, :3].astype(np.float64) * step
            return values.astype(np.float32)
        if encoded.encoding == PREDICTED:
            if not self.can_predict:
                raise ValueError("a predicted frame needs the mesh's prediction weights")
            expected = FLOATS_PER_BONE_TRANSFORM * self._num_bones
            if len(encoded.bone_transforms) != expected:
                raise ValueError(f"a predicted frame needs {expected} transform floats, got "
                                 f"{len(encoded.bone_transforms)}")
            records = decode_records(encoded.data, self.vertex_count)
            transforms = np.array(encoded.bone_transforms, dtype=np.float32).reshape(
                self._num_bones, FLOATS_PER_BONE_TRANSFORM)
            assert self._rest is not None and self._bones is not None \
                and self._weights is not None  # can_predict
            predicted = predict_positions(self._rest, self._bones, self._weights, transforms)
            residual = unzigzag(records[:, :3]).astype(np.float64)
            values = predicted.astype(np.float64) + residual * step
            return values.astype(np.float32)
        raise ValueError(f"a frame in an unknown encoding ({encoded.encoding})")
