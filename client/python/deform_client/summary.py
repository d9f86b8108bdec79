"""What deformd says about a loaded mesh, as typed objects wrapping the protobuf messages.

MeshSummary (LoadMesh's READY answer, ListMeshes, GetMeshInfo) with its joints, bones and bone
surfaces as frozen dataclasses; every object keeps the message it was made from in `message`, for
the fields not copied here. MeshInfo (GetMeshInfo's answer) adds the geometry as numpy arrays.
Enums are given by name without their prefix ("QUATERNION", "THROUGH_BODY").
"""

from __future__ import annotations

import dataclasses
from typing import Any, Optional, Tuple

import numpy as np

from . import codec
from .stubs import pb


def _enum_name(enum: Any, value: int, prefix: str) -> str:
    try:
        return str(enum.Name(value)).removeprefix(prefix)
    except ValueError:
        return str(value)


@dataclasses.dataclass(frozen=True)
class DegreeOfFreedom:
    name: str                                # e.g. "flexion"
    axis: Tuple[float, float, float]         # unit axis, rest frame
    min_degrees: float
    max_degrees: float


@dataclasses.dataclass(frozen=True)
class Joint:
    name: str
    index: int
    rest_position: Tuple[float, ...]         # 3 values
    dofs: Tuple[DegreeOfFreedom, ...]
    has_region: bool                         # an inner joint with a material profile


@dataclasses.dataclass(frozen=True)
class Bone:
    head_joint: int                          # index into MeshSummary.joints
    tail_joint: int
    parent_bone: int                         # -1 for a root bone


@dataclasses.dataclass(frozen=True)
class BoneSurfaceInfo:
    """A bone surface as the summary lists it (MeshInfo.bone_surfaces adds its geometry)."""
    name: str
    bone: int
    blend_bone: int                          # -1: none
    blend: float
    vertex_count: int
    triangle_count: int


@dataclasses.dataclass(frozen=True)
class MeshSummary:
    """A loaded mesh. `message` is the MeshSummary message it wraps."""
    mesh_id: str
    name: str
    vertex_count: int                        # vertices of frames, in the file's order
    triangle_count: int
    solved_vertex_count: int                 # after welding glTF seams
    joints: Tuple[Joint, ...]
    bones: Tuple[Bone, ...]
    bone_count: int
    bone_surfaces: Tuple[BoneSurfaceInfo, ...]  # in the order frames carry their transforms
    warnings: Tuple[str, ...]                # the binding report's, one line each
    binding: str                             # THROUGH_BODY or WEIGHTS
    rotation_blend: str                      # QUATERNION, LINEAR, ...
    units: str                               # where the file states them, else ""
    up_axis: str
    factor_bytes: int
    factor_float32: bool
    float32_probe_error: float               # negative where no probe ran
    precompute_ms: float
    factor_ms: float
    open_streams: int
    linear_response_bytes: int
    constraints: pb.Constraints              # the constraints in use
    message: pb.MeshSummary = dataclasses.field(repr=False, compare=False)

    @classmethod
    def from_message(cls, message: pb.MeshSummary) -> "MeshSummary":
        joints = tuple(
            Joint(name=j.name, index=j.index, rest_position=tuple(j.rest_position),
                  dofs=tuple(DegreeOfFreedom(d.name, (d.axis[0], d.axis[1], d.axis[2])
                                             if len(d.axis) == 3 else (0.0, 0.0, 0.0),
                                             d.min_degrees, d.max_degrees) for d in j.dofs),
                  has_region=j.has_region)
            for j in message.joints)
        return cls(
            mesh_id=message.mesh_id, name=message.name, vertex_count=message.vertex_count,
            triangle_count=message.triangle_count,
            solved_vertex_count=message.solved_vertex_count, joints=joints,
            bones=tuple(Bone(b.head_joint, b.tail_joint, b.parent_bone) for b in message.bones),
            bone_count=message.bone_count,
            bone_surfaces=tuple(BoneSurfaceInfo(s.name, s.bone, s.blend_bone, s.blend,
                                                s.vertex_count, s.triangle_count)
                                for s in message.bone_surfaces),
            warnings=tuple(message.warnings),
            binding=_enum_name(pb.Binding, message.binding, "BINDING_"),
            rotation_blend=_enum_name(pb.RotationBlend, message.rotation_blend,
                                      "ROTATION_BLEND_"),
            units=message.units, up_axis=message.up_axis, factor_bytes=message.factor_bytes,
            factor_float32=message.factor_float32,
            float32_probe_error=message.float32_probe_error,
            precompute_ms=message.precompute_ms, factor_ms=message.factor_ms,
            open_streams=message.open_streams,
            linear_response_bytes=message.linear_response_bytes,
            constraints=message.constraints, message=message)

    def joint(self, name: str) -> Joint:
        """The joint called `name`; KeyError naming the joints there are otherwise."""
        for joint in self.joints:
            if joint.name == name:
                return joint
        raise KeyError(f"no joint {name!r} in {self.mesh_id} (joints: "
                       f"{', '.join(j.name for j in self.joints)})")


@dataclasses.dataclass
class BoneSurface:
    """A bone surface of a loaded mesh (MeshSummary.bone_surfaces) and, with geometry, its rest
    positions ((N, 3) float32) and triangles ((T, 3) uint32)."""
    name: str
    bone: int
    blend_bone: int  # -1: none
    blend: float
    rest_positions: Optional[np.ndarray] = dataclasses.field(default=None, repr=False)
    triangles: Optional[np.ndarray] = dataclasses.field(default=None, repr=False)


def _triangles(data: bytes) -> np.ndarray:
    return np.frombuffer(data, dtype="<u4").astype(np.uint32).reshape(-1, 3)


class MeshInfo:
    """GetMeshInfo's answer: `summary` (MeshSummary), `bone_surfaces` (BoneSurface, in the order
    frames carry their transforms), and when asked for, `rest_positions` ((V, 3) float32),
    `triangles` ((T, 3) uint32), each bone surface's geometry and `prediction_weights`
    (PredictionWeights); None when not asked for. `response` is the GetMeshInfoResponse as
    received."""

    def __init__(self, response: pb.GetMeshInfoResponse, geometry: bool,
                 prediction_weights: bool):
        self.response = response
        self.summary = MeshSummary.from_message(response.summary)
        self.rest_positions: Optional[np.ndarray] = None
        self.triangles: Optional[np.ndarray] = None
        self.prediction_weights: Optional[pb.PredictionWeights] = None
        self.bone_surfaces = [BoneSurface(s.name, s.bone, s.blend_bone, s.blend)
                              for s in response.summary.bone_surfaces]
        if geometry:
            self.rest_positions = codec.decode_float32(response.rest_positions,
                                                       response.summary.vertex_count)
            self.triangles = _triangles(response.triangles)
            for surface, shape in zip(self.bone_surfaces, response.bone_surfaces):
                surface.rest_positions = codec.decode_float32(
                    shape.rest_positions, len(shape.rest_positions) // 12)
                surface.triangles = _triangles(shape.triangles)
        if prediction_weights:
            self.prediction_weights = response.prediction_weights
