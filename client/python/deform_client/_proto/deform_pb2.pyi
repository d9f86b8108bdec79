from google.protobuf.internal import containers as _containers
from google.protobuf.internal import enum_type_wrapper as _enum_type_wrapper
from google.protobuf import descriptor as _descriptor
from google.protobuf import message as _message
from typing import ClassVar as _ClassVar, Iterable as _Iterable, Mapping as _Mapping, Optional as _Optional, Union as _Union

BINDING_THROUGH_BODY: Binding
BINDING_UNSPECIFIED: Binding
BINDING_WEIGHTS: Binding
DESCRIPTOR: _descriptor.FileDescriptor
FRAME_ENCODING_FLOAT32: FrameEncoding
FRAME_ENCODING_PREDICTED: FrameEncoding
FRAME_ENCODING_QUANTIZED: FrameEncoding
FRAME_ENCODING_UNSPECIFIED: FrameEncoding
MESH_FORMAT_GLTF: MeshFormat
MESH_FORMAT_OBJ: MeshFormat
MESH_FORMAT_OFF: MeshFormat
MESH_FORMAT_PLY: MeshFormat
MESH_FORMAT_STL: MeshFormat
MESH_FORMAT_UNSPECIFIED: MeshFormat
ROTATION_BLEND_LINEAR: RotationBlend
ROTATION_BLEND_QUATERNION: RotationBlend
ROTATION_BLEND_UNSPECIFIED: RotationBlend
SKELETON_FORMAT_JSON: SkeletonFormat
SKELETON_FORMAT_TGF: SkeletonFormat
SKELETON_FORMAT_UNSPECIFIED: SkeletonFormat
SKIN_WEIGHTS_FORMAT_CSV: SkinWeightsFormat
SKIN_WEIGHTS_FORMAT_DMAT: SkinWeightsFormat
SKIN_WEIGHTS_FORMAT_UNSPECIFIED: SkinWeightsFormat

class BoneInfo(_message.Message):
    __slots__ = ["head_joint", "parent_bone", "tail_joint"]
    HEAD_JOINT_FIELD_NUMBER: _ClassVar[int]
    PARENT_BONE_FIELD_NUMBER: _ClassVar[int]
    TAIL_JOINT_FIELD_NUMBER: _ClassVar[int]
    head_joint: int
    parent_bone: int
    tail_joint: int
    def __init__(self, head_joint: _Optional[int] = ..., tail_joint: _Optional[int] = ..., parent_bone: _Optional[int] = ...) -> None: ...

class BoneSurfaceGeometry(_message.Message):
    __slots__ = ["rest_positions", "triangles"]
    REST_POSITIONS_FIELD_NUMBER: _ClassVar[int]
    TRIANGLES_FIELD_NUMBER: _ClassVar[int]
    rest_positions: bytes
    triangles: bytes
    def __init__(self, rest_positions: _Optional[bytes] = ..., triangles: _Optional[bytes] = ...) -> None: ...

class BoneSurfaceInfo(_message.Message):
    __slots__ = ["blend", "blend_bone", "bone", "name", "triangle_count", "vertex_count"]
    BLEND_BONE_FIELD_NUMBER: _ClassVar[int]
    BLEND_FIELD_NUMBER: _ClassVar[int]
    BONE_FIELD_NUMBER: _ClassVar[int]
    NAME_FIELD_NUMBER: _ClassVar[int]
    TRIANGLE_COUNT_FIELD_NUMBER: _ClassVar[int]
    VERTEX_COUNT_FIELD_NUMBER: _ClassVar[int]
    blend: float
    blend_bone: int
    bone: int
    name: str
    triangle_count: int
    vertex_count: int
    def __init__(self, name: _Optional[str] = ..., bone: _Optional[int] = ..., blend_bone: _Optional[int] = ..., blend: _Optional[float] = ..., vertex_count: _Optional[int] = ..., triangle_count: _Optional[int] = ...) -> None: ...

class BoneSurfaceUpload(_message.Message):
    __slots__ = ["blend", "blend_bone", "bone", "format", "mesh", "name"]
    BLEND_BONE_FIELD_NUMBER: _ClassVar[int]
    BLEND_FIELD_NUMBER: _ClassVar[int]
    BONE_FIELD_NUMBER: _ClassVar[int]
    FORMAT_FIELD_NUMBER: _ClassVar[int]
    MESH_FIELD_NUMBER: _ClassVar[int]
    NAME_FIELD_NUMBER: _ClassVar[int]
    blend: float
    blend_bone: str
    bone: str
    format: MeshFormat
    mesh: bytes
    name: str
    def __init__(self, name: _Optional[str] = ..., format: _Optional[_Union[MeshFormat, str]] = ..., mesh: _Optional[bytes] = ..., bone: _Optional[str] = ..., blend_bone: _Optional[str] = ..., blend: _Optional[float] = ...) -> None: ...

class Constraints(_message.Message):
    __slots__ = ["contact_margin", "contacts", "keep_volume"]
    CONTACTS_FIELD_NUMBER: _ClassVar[int]
    CONTACT_MARGIN_FIELD_NUMBER: _ClassVar[int]
    KEEP_VOLUME_FIELD_NUMBER: _ClassVar[int]
    contact_margin: float
    contacts: bool
    keep_volume: bool
    def __init__(self, contacts: bool = ..., keep_volume: bool = ..., contact_margin: _Optional[float] = ...) -> None: ...

class ContactQuery(_message.Message):
    __slots__ = ["sequence", "tool"]
    SEQUENCE_FIELD_NUMBER: _ClassVar[int]
    TOOL_FIELD_NUMBER: _ClassVar[int]
    sequence: int
    tool: ToolState
    def __init__(self, sequence: _Optional[int] = ..., tool: _Optional[_Union[ToolState, _Mapping]] = ...) -> None: ...

class ContactQueryStart(_message.Message):
    __slots__ = ["deform_stream_id", "mesh_id", "stiffness"]
    DEFORM_STREAM_ID_FIELD_NUMBER: _ClassVar[int]
    MESH_ID_FIELD_NUMBER: _ClassVar[int]
    STIFFNESS_FIELD_NUMBER: _ClassVar[int]
    deform_stream_id: int
    mesh_id: str
    stiffness: float
    def __init__(self, mesh_id: _Optional[str] = ..., deform_stream_id: _Optional[int] = ..., stiffness: _Optional[float] = ...) -> None: ...

class ContactQueryStarted(_message.Message):
    __slots__ = ["bounding_box_diagonal", "stiffness"]
    BOUNDING_BOX_DIAGONAL_FIELD_NUMBER: _ClassVar[int]
    STIFFNESS_FIELD_NUMBER: _ClassVar[int]
    bounding_box_diagonal: float
    stiffness: float
    def __init__(self, bounding_box_diagonal: _Optional[float] = ..., stiffness: _Optional[float] = ...) -> None: ...

class ContactResult(_message.Message):
    __slots__ = ["depth", "force", "frame_number", "frame_sequence", "material_weight", "normal", "point", "sequence", "signed_distance", "tool_point"]
    DEPTH_FIELD_NUMBER: _ClassVar[int]
    FORCE_FIELD_NUMBER: _ClassVar[int]
    FRAME_NUMBER_FIELD_NUMBER: _ClassVar[int]
    FRAME_SEQUENCE_FIELD_NUMBER: _ClassVar[int]
    MATERIAL_WEIGHT_FIELD_NUMBER: _ClassVar[int]
    NORMAL_FIELD_NUMBER: _ClassVar[int]
    POINT_FIELD_NUMBER: _ClassVar[int]
    SEQUENCE_FIELD_NUMBER: _ClassVar[int]
    SIGNED_DISTANCE_FIELD_NUMBER: _ClassVar[int]
    TOOL_POINT_FIELD_NUMBER: _ClassVar[int]
    depth: float
    force: Vector3
    frame_number: int
    frame_sequence: int
    material_weight: float
    normal: Vector3
    point: Vector3
    sequence: int
    signed_distance: float
    tool_point: Vector3
    def __init__(self, sequence: _Optional[int] = ..., point: _Optional[_Union[Vector3, _Mapping]] = ..., normal: _Optional[_Union[Vector3, _Mapping]] = ..., depth: _Optional[float] = ..., force: _Optional[_Union[Vector3, _Mapping]] = ..., signed_distance: _Optional[float] = ..., material_weight: _Optional[float] = ..., frame_number: _Optional[int] = ..., frame_sequence: _Optional[int] = ..., tool_point: _Optional[_Union[Vector3, _Mapping]] = ...) -> None: ...

class DeformFrame(_message.Message):
    __slots__ = ["bone_transforms", "clamped_angles", "client_timestamp_ns", "constraints", "encoded", "mesh_unloaded", "positions", "sequence", "skipped_poses", "stiffness_version", "stream_id", "timings"]
    BONE_TRANSFORMS_FIELD_NUMBER: _ClassVar[int]
    CLAMPED_ANGLES_FIELD_NUMBER: _ClassVar[int]
    CLIENT_TIMESTAMP_NS_FIELD_NUMBER: _ClassVar[int]
    CONSTRAINTS_FIELD_NUMBER: _ClassVar[int]
    ENCODED_FIELD_NUMBER: _ClassVar[int]
    MESH_UNLOADED_FIELD_NUMBER: _ClassVar[int]
    POSITIONS_FIELD_NUMBER: _ClassVar[int]
    SEQUENCE_FIELD_NUMBER: _ClassVar[int]
    SKIPPED_POSES_FIELD_NUMBER: _ClassVar[int]
    STIFFNESS_VERSION_FIELD_NUMBER: _ClassVar[int]
    STREAM_ID_FIELD_NUMBER: _ClassVar[int]
    TIMINGS_FIELD_NUMBER: _ClassVar[int]
    bone_transforms: bytes
    clamped_angles: int
    client_timestamp_ns: int
    constraints: FrameConstraints
    encoded: EncodedPositions
    mesh_unloaded: bool
    positions: bytes
    sequence: int
    skipped_poses: int
    stiffness_version: int
    stream_id: int
    timings: FrameTimings
    def __init__(self, sequence: _Optional[int] = ..., client_timestamp_ns: _Optional[int] = ..., stiffness_version: _Optional[int] = ..., skipped_poses: _Optional[int] = ..., clamped_angles: _Optional[int] = ..., mesh_unloaded: bool = ..., timings: _Optional[_Union[FrameTimings, _Mapping]] = ..., positions: _Optional[bytes] = ..., encoded: _Optional[_Union[EncodedPositions, _Mapping]] = ..., bone_transforms: _Optional[bytes] = ..., constraints: _Optional[_Union[FrameConstraints, _Mapping]] = ..., stream_id: _Optional[int] = ...) -> None: ...

class DeformRequest(_message.Message):
    __slots__ = ["pose", "start", "stiffness"]
    POSE_FIELD_NUMBER: _ClassVar[int]
    START_FIELD_NUMBER: _ClassVar[int]
    STIFFNESS_FIELD_NUMBER: _ClassVar[int]
    pose: PoseUpdate
    start: DeformStart
    stiffness: StiffnessUpdate
    def __init__(self, start: _Optional[_Union[DeformStart, _Mapping]] = ..., pose: _Optional[_Union[PoseUpdate, _Mapping]] = ..., stiffness: _Optional[_Union[StiffnessUpdate, _Mapping]] = ...) -> None: ...

class DeformResponse(_message.Message):
    __slots__ = ["frame", "notice"]
    FRAME_FIELD_NUMBER: _ClassVar[int]
    NOTICE_FIELD_NUMBER: _ClassVar[int]
    frame: DeformFrame
    notice: Notice
    def __init__(self, frame: _Optional[_Union[DeformFrame, _Mapping]] = ..., notice: _Optional[_Union[Notice, _Mapping]] = ...) -> None: ...

class DeformStart(_message.Message):
    __slots__ = ["encoding", "max_error", "mesh_id"]
    ENCODING_FIELD_NUMBER: _ClassVar[int]
    MAX_ERROR_FIELD_NUMBER: _ClassVar[int]
    MESH_ID_FIELD_NUMBER: _ClassVar[int]
    encoding: FrameEncoding
    max_error: float
    mesh_id: str
    def __init__(self, mesh_id: _Optional[str] = ..., encoding: _Optional[_Union[FrameEncoding, str]] = ..., max_error: _Optional[float] = ...) -> None: ...

class DegreeOfFreedom(_message.Message):
    __slots__ = ["axis", "max_degrees", "min_degrees", "name"]
    AXIS_FIELD_NUMBER: _ClassVar[int]
    MAX_DEGREES_FIELD_NUMBER: _ClassVar[int]
    MIN_DEGREES_FIELD_NUMBER: _ClassVar[int]
    NAME_FIELD_NUMBER: _ClassVar[int]
    axis: _containers.RepeatedScalarFieldContainer[float]
    max_degrees: float
    min_degrees: float
    name: str
    def __init__(self, name: _Optional[str] = ..., axis: _Optional[_Iterable[float]] = ..., min_degrees: _Optional[float] = ..., max_degrees: _Optional[float] = ...) -> None: ...

class EncodedPositions(_message.Message):
    __slots__ = ["bone_transforms", "data", "encoding", "max_error", "origin", "step"]
    BONE_TRANSFORMS_FIELD_NUMBER: _ClassVar[int]
    DATA_FIELD_NUMBER: _ClassVar[int]
    ENCODING_FIELD_NUMBER: _ClassVar[int]
    MAX_ERROR_FIELD_NUMBER: _ClassVar[int]
    ORIGIN_FIELD_NUMBER: _ClassVar[int]
    STEP_FIELD_NUMBER: _ClassVar[int]
    bone_transforms: _containers.RepeatedScalarFieldContainer[float]
    data: bytes
    encoding: FrameEncoding
    max_error: float
    origin: _containers.RepeatedScalarFieldContainer[float]
    step: float
    def __init__(self, encoding: _Optional[_Union[FrameEncoding, str]] = ..., origin: _Optional[_Iterable[float]] = ..., step: _Optional[float] = ..., max_error: _Optional[float] = ..., data: _Optional[bytes] = ..., bone_transforms: _Optional[_Iterable[float]] = ...) -> None: ...

class FrameConstraints(_message.Message):
    __slots__ = ["contacts", "max_depth_after", "penetrating_after", "penetrating_before", "tool_contacts", "tool_max_depth_after", "tool_penetrating_after", "tool_penetrating_before", "tools_unresolved", "unresolved", "volume_change"]
    CONTACTS_FIELD_NUMBER: _ClassVar[int]
    MAX_DEPTH_AFTER_FIELD_NUMBER: _ClassVar[int]
    PENETRATING_AFTER_FIELD_NUMBER: _ClassVar[int]
    PENETRATING_BEFORE_FIELD_NUMBER: _ClassVar[int]
    TOOLS_UNRESOLVED_FIELD_NUMBER: _ClassVar[int]
    TOOL_CONTACTS_FIELD_NUMBER: _ClassVar[int]
    TOOL_MAX_DEPTH_AFTER_FIELD_NUMBER: _ClassVar[int]
    TOOL_PENETRATING_AFTER_FIELD_NUMBER: _ClassVar[int]
    TOOL_PENETRATING_BEFORE_FIELD_NUMBER: _ClassVar[int]
    UNRESOLVED_FIELD_NUMBER: _ClassVar[int]
    VOLUME_CHANGE_FIELD_NUMBER: _ClassVar[int]
    contacts: int
    max_depth_after: float
    penetrating_after: int
    penetrating_before: int
    tool_contacts: int
    tool_max_depth_after: float
    tool_penetrating_after: int
    tool_penetrating_before: int
    tools_unresolved: bool
    unresolved: bool
    volume_change: float
    def __init__(self, penetrating_before: _Optional[int] = ..., penetrating_after: _Optional[int] = ..., max_depth_after: _Optional[float] = ..., unresolved: bool = ..., contacts: _Optional[int] = ..., volume_change: _Optional[float] = ..., tool_penetrating_before: _Optional[int] = ..., tool_penetrating_after: _Optional[int] = ..., tool_max_depth_after: _Optional[float] = ..., tool_contacts: _Optional[int] = ..., tools_unresolved: bool = ...) -> None: ...

class FrameTimings(_message.Message):
    __slots__ = ["batch_frames", "constraint_ms", "encode_ms", "queue_ms", "rhs_ms", "solve_ms", "solve_parts"]
    BATCH_FRAMES_FIELD_NUMBER: _ClassVar[int]
    CONSTRAINT_MS_FIELD_NUMBER: _ClassVar[int]
    ENCODE_MS_FIELD_NUMBER: _ClassVar[int]
    QUEUE_MS_FIELD_NUMBER: _ClassVar[int]
    RHS_MS_FIELD_NUMBER: _ClassVar[int]
    SOLVE_MS_FIELD_NUMBER: _ClassVar[int]
    SOLVE_PARTS_FIELD_NUMBER: _ClassVar[int]
    batch_frames: int
    constraint_ms: float
    encode_ms: float
    queue_ms: float
    rhs_ms: float
    solve_ms: float
    solve_parts: int
    def __init__(self, queue_ms: _Optional[float] = ..., rhs_ms: _Optional[float] = ..., solve_ms: _Optional[float] = ..., encode_ms: _Optional[float] = ..., batch_frames: _Optional[int] = ..., solve_parts: _Optional[int] = ..., constraint_ms: _Optional[float] = ...) -> None: ...

class GetMeshInfoRequest(_message.Message):
    __slots__ = ["include_geometry", "include_prediction_weights", "mesh_id"]
    INCLUDE_GEOMETRY_FIELD_NUMBER: _ClassVar[int]
    INCLUDE_PREDICTION_WEIGHTS_FIELD_NUMBER: _ClassVar[int]
    MESH_ID_FIELD_NUMBER: _ClassVar[int]
    include_geometry: bool
    include_prediction_weights: bool
    mesh_id: str
    def __init__(self, mesh_id: _Optional[str] = ..., include_geometry: bool = ..., include_prediction_weights: bool = ...) -> None: ...

class GetMeshInfoResponse(_message.Message):
    __slots__ = ["bone_surfaces", "prediction_weights", "rest_positions", "summary", "triangles"]
    BONE_SURFACES_FIELD_NUMBER: _ClassVar[int]
    PREDICTION_WEIGHTS_FIELD_NUMBER: _ClassVar[int]
    REST_POSITIONS_FIELD_NUMBER: _ClassVar[int]
    SUMMARY_FIELD_NUMBER: _ClassVar[int]
    TRIANGLES_FIELD_NUMBER: _ClassVar[int]
    bone_surfaces: _containers.RepeatedCompositeFieldContainer[BoneSurfaceGeometry]
    prediction_weights: PredictionWeights
    rest_positions: bytes
    summary: MeshSummary
    triangles: bytes
    def __init__(self, summary: _Optional[_Union[MeshSummary, _Mapping]] = ..., rest_positions: _Optional[bytes] = ..., triangles: _Optional[bytes] = ..., prediction_weights: _Optional[_Union[PredictionWeights, _Mapping]] = ..., bone_surfaces: _Optional[_Iterable[_Union[BoneSurfaceGeometry, _Mapping]]] = ...) -> None: ...

class JointAngle(_message.Message):
    __slots__ = ["axis", "degrees", "joint"]
    AXIS_FIELD_NUMBER: _ClassVar[int]
    DEGREES_FIELD_NUMBER: _ClassVar[int]
    JOINT_FIELD_NUMBER: _ClassVar[int]
    axis: str
    degrees: float
    joint: str
    def __init__(self, joint: _Optional[str] = ..., axis: _Optional[str] = ..., degrees: _Optional[float] = ...) -> None: ...

class JointInfo(_message.Message):
    __slots__ = ["dofs", "has_region", "index", "name", "rest_position"]
    DOFS_FIELD_NUMBER: _ClassVar[int]
    HAS_REGION_FIELD_NUMBER: _ClassVar[int]
    INDEX_FIELD_NUMBER: _ClassVar[int]
    NAME_FIELD_NUMBER: _ClassVar[int]
    REST_POSITION_FIELD_NUMBER: _ClassVar[int]
    dofs: _containers.RepeatedCompositeFieldContainer[DegreeOfFreedom]
    has_region: bool
    index: int
    name: str
    rest_position: _containers.RepeatedScalarFieldContainer[float]
    def __init__(self, name: _Optional[str] = ..., index: _Optional[int] = ..., rest_position: _Optional[_Iterable[float]] = ..., dofs: _Optional[_Iterable[_Union[DegreeOfFreedom, _Mapping]]] = ..., has_region: bool = ...) -> None: ...

class JointMaterial(_message.Message):
    __slots__ = ["rigid", "seam", "soft"]
    RIGID_FIELD_NUMBER: _ClassVar[int]
    SEAM_FIELD_NUMBER: _ClassVar[int]
    SOFT_FIELD_NUMBER: _ClassVar[int]
    rigid: float
    seam: float
    soft: float
    def __init__(self, rigid: _Optional[float] = ..., soft: _Optional[float] = ..., seam: _Optional[float] = ...) -> None: ...

class JointMaterialUpdate(_message.Message):
    __slots__ = ["joint", "material"]
    JOINT_FIELD_NUMBER: _ClassVar[int]
    MATERIAL_FIELD_NUMBER: _ClassVar[int]
    joint: str
    material: JointMaterial
    def __init__(self, joint: _Optional[str] = ..., material: _Optional[_Union[JointMaterial, _Mapping]] = ...) -> None: ...

class JointRadius(_message.Message):
    __slots__ = ["joint", "radius"]
    JOINT_FIELD_NUMBER: _ClassVar[int]
    RADIUS_FIELD_NUMBER: _ClassVar[int]
    joint: str
    radius: float
    def __init__(self, joint: _Optional[str] = ..., radius: _Optional[float] = ...) -> None: ...

class JointRotation(_message.Message):
    __slots__ = ["joint", "w", "x", "y", "z"]
    JOINT_FIELD_NUMBER: _ClassVar[int]
    W_FIELD_NUMBER: _ClassVar[int]
    X_FIELD_NUMBER: _ClassVar[int]
    Y_FIELD_NUMBER: _ClassVar[int]
    Z_FIELD_NUMBER: _ClassVar[int]
    joint: str
    w: float
    x: float
    y: float
    z: float
    def __init__(self, joint: _Optional[str] = ..., w: _Optional[float] = ..., x: _Optional[float] = ..., y: _Optional[float] = ..., z: _Optional[float] = ...) -> None: ...

class ListMeshesRequest(_message.Message):
    __slots__ = []
    def __init__(self) -> None: ...

class ListMeshesResponse(_message.Message):
    __slots__ = ["meshes"]
    MESHES_FIELD_NUMBER: _ClassVar[int]
    meshes: _containers.RepeatedCompositeFieldContainer[MeshSummary]
    def __init__(self, meshes: _Optional[_Iterable[_Union[MeshSummary, _Mapping]]] = ...) -> None: ...

class LoadMeshHeader(_message.Message):
    __slots__ = ["name", "options", "phantom", "upload"]
    NAME_FIELD_NUMBER: _ClassVar[int]
    OPTIONS_FIELD_NUMBER: _ClassVar[int]
    PHANTOM_FIELD_NUMBER: _ClassVar[int]
    UPLOAD_FIELD_NUMBER: _ClassVar[int]
    name: str
    options: MethodOptions
    phantom: PhantomSource
    upload: UploadSource
    def __init__(self, name: _Optional[str] = ..., phantom: _Optional[_Union[PhantomSource, _Mapping]] = ..., upload: _Optional[_Union[UploadSource, _Mapping]] = ..., options: _Optional[_Union[MethodOptions, _Mapping]] = ...) -> None: ...

class LoadMeshRequest(_message.Message):
    __slots__ = ["chunk", "header"]
    CHUNK_FIELD_NUMBER: _ClassVar[int]
    HEADER_FIELD_NUMBER: _ClassVar[int]
    chunk: bytes
    header: LoadMeshHeader
    def __init__(self, header: _Optional[_Union[LoadMeshHeader, _Mapping]] = ..., chunk: _Optional[bytes] = ...) -> None: ...

class LoadMeshResponse(_message.Message):
    __slots__ = ["elapsed_ms", "mesh", "stage"]
    class Stage(int, metaclass=_enum_type_wrapper.EnumTypeWrapper):
        __slots__ = []
    ELAPSED_MS_FIELD_NUMBER: _ClassVar[int]
    MESH_FIELD_NUMBER: _ClassVar[int]
    STAGE_FACTORISED: LoadMeshResponse.Stage
    STAGE_FIELD_NUMBER: _ClassVar[int]
    STAGE_READY: LoadMeshResponse.Stage
    STAGE_RECEIVED: LoadMeshResponse.Stage
    STAGE_UNSPECIFIED: LoadMeshResponse.Stage
    STAGE_VALIDATED: LoadMeshResponse.Stage
    STAGE_WEIGHTS: LoadMeshResponse.Stage
    elapsed_ms: float
    mesh: MeshSummary
    stage: LoadMeshResponse.Stage
    def __init__(self, stage: _Optional[_Union[LoadMeshResponse.Stage, str]] = ..., elapsed_ms: _Optional[float] = ..., mesh: _Optional[_Union[MeshSummary, _Mapping]] = ...) -> None: ...

class MeshSummary(_message.Message):
    __slots__ = ["binding", "bone_count", "bone_surfaces", "bones", "constraints", "factor_bytes", "factor_float32", "factor_ms", "float32_probe_error", "joints", "linear_response_bytes", "mesh_id", "name", "open_streams", "precompute_ms", "rotation_blend", "solved_vertex_count", "triangle_count", "units", "up_axis", "vertex_count", "warnings"]
    BINDING_FIELD_NUMBER: _ClassVar[int]
    BONES_FIELD_NUMBER: _ClassVar[int]
    BONE_COUNT_FIELD_NUMBER: _ClassVar[int]
    BONE_SURFACES_FIELD_NUMBER: _ClassVar[int]
    CONSTRAINTS_FIELD_NUMBER: _ClassVar[int]
    FACTOR_BYTES_FIELD_NUMBER: _ClassVar[int]
    FACTOR_FLOAT32_FIELD_NUMBER: _ClassVar[int]
    FACTOR_MS_FIELD_NUMBER: _ClassVar[int]
    FLOAT32_PROBE_ERROR_FIELD_NUMBER: _ClassVar[int]
    JOINTS_FIELD_NUMBER: _ClassVar[int]
    LINEAR_RESPONSE_BYTES_FIELD_NUMBER: _ClassVar[int]
    MESH_ID_FIELD_NUMBER: _ClassVar[int]
    NAME_FIELD_NUMBER: _ClassVar[int]
    OPEN_STREAMS_FIELD_NUMBER: _ClassVar[int]
    PRECOMPUTE_MS_FIELD_NUMBER: _ClassVar[int]
    ROTATION_BLEND_FIELD_NUMBER: _ClassVar[int]
    SOLVED_VERTEX_COUNT_FIELD_NUMBER: _ClassVar[int]
    TRIANGLE_COUNT_FIELD_NUMBER: _ClassVar[int]
    UNITS_FIELD_NUMBER: _ClassVar[int]
    UP_AXIS_FIELD_NUMBER: _ClassVar[int]
    VERTEX_COUNT_FIELD_NUMBER: _ClassVar[int]
    WARNINGS_FIELD_NUMBER: _ClassVar[int]
    binding: Binding
    bone_count: int
    bone_surfaces: _containers.RepeatedCompositeFieldContainer[BoneSurfaceInfo]
    bones: _containers.RepeatedCompositeFieldContainer[BoneInfo]
    constraints: Constraints
    factor_bytes: int
    factor_float32: bool
    factor_ms: float
    float32_probe_error: float
    joints: _containers.RepeatedCompositeFieldContainer[JointInfo]
    linear_response_bytes: int
    mesh_id: str
    name: str
    open_streams: int
    precompute_ms: float
    rotation_blend: RotationBlend
    solved_vertex_count: int
    triangle_count: int
    units: str
    up_axis: str
    vertex_count: int
    warnings: _containers.RepeatedScalarFieldContainer[str]
    def __init__(self, mesh_id: _Optional[str] = ..., name: _Optional[str] = ..., vertex_count: _Optional[int] = ..., triangle_count: _Optional[int] = ..., joints: _Optional[_Iterable[_Union[JointInfo, _Mapping]]] = ..., bone_count: _Optional[int] = ..., factor_bytes: _Optional[int] = ..., precompute_ms: _Optional[float] = ..., factor_ms: _Optional[float] = ..., open_streams: _Optional[int] = ..., rotation_blend: _Optional[_Union[RotationBlend, str]] = ..., linear_response_bytes: _Optional[int] = ..., warnings: _Optional[_Iterable[str]] = ..., binding: _Optional[_Union[Binding, str]] = ..., bones: _Optional[_Iterable[_Union[BoneInfo, _Mapping]]] = ..., units: _Optional[str] = ..., up_axis: _Optional[str] = ..., solved_vertex_count: _Optional[int] = ..., factor_float32: bool = ..., float32_probe_error: _Optional[float] = ..., bone_surfaces: _Optional[_Iterable[_Union[BoneSurfaceInfo, _Mapping]]] = ..., constraints: _Optional[_Union[Constraints, _Mapping]] = ...) -> None: ...

class MethodOptions(_message.Message):
    __slots__ = ["constraints", "default_material", "linear_blend_segments", "region_radii", "region_radius_factor", "rigid_weight_tolerance", "rotation_blend"]
    CONSTRAINTS_FIELD_NUMBER: _ClassVar[int]
    DEFAULT_MATERIAL_FIELD_NUMBER: _ClassVar[int]
    LINEAR_BLEND_SEGMENTS_FIELD_NUMBER: _ClassVar[int]
    REGION_RADII_FIELD_NUMBER: _ClassVar[int]
    REGION_RADIUS_FACTOR_FIELD_NUMBER: _ClassVar[int]
    RIGID_WEIGHT_TOLERANCE_FIELD_NUMBER: _ClassVar[int]
    ROTATION_BLEND_FIELD_NUMBER: _ClassVar[int]
    constraints: Constraints
    default_material: JointMaterial
    linear_blend_segments: int
    region_radii: _containers.RepeatedCompositeFieldContainer[JointRadius]
    region_radius_factor: float
    rigid_weight_tolerance: float
    rotation_blend: RotationBlend
    def __init__(self, region_radius_factor: _Optional[float] = ..., region_radii: _Optional[_Iterable[_Union[JointRadius, _Mapping]]] = ..., default_material: _Optional[_Union[JointMaterial, _Mapping]] = ..., rotation_blend: _Optional[_Union[RotationBlend, str]] = ..., linear_blend_segments: _Optional[int] = ..., rigid_weight_tolerance: _Optional[float] = ..., constraints: _Optional[_Union[Constraints, _Mapping]] = ...) -> None: ...

class Notice(_message.Message):
    __slots__ = ["factor_ms", "kind", "message", "sequence", "stiffness_version"]
    class Kind(int, metaclass=_enum_type_wrapper.EnumTypeWrapper):
        __slots__ = []
    FACTOR_MS_FIELD_NUMBER: _ClassVar[int]
    KIND_CREDENTIALS_REVOKED: Notice.Kind
    KIND_FIELD_NUMBER: _ClassVar[int]
    KIND_POSE_REJECTED: Notice.Kind
    KIND_STIFFNESS_APPLIED: Notice.Kind
    KIND_STIFFNESS_REJECTED: Notice.Kind
    KIND_UNSPECIFIED: Notice.Kind
    MESSAGE_FIELD_NUMBER: _ClassVar[int]
    SEQUENCE_FIELD_NUMBER: _ClassVar[int]
    STIFFNESS_VERSION_FIELD_NUMBER: _ClassVar[int]
    factor_ms: float
    kind: Notice.Kind
    message: str
    sequence: int
    stiffness_version: int
    def __init__(self, kind: _Optional[_Union[Notice.Kind, str]] = ..., sequence: _Optional[int] = ..., stiffness_version: _Optional[int] = ..., message: _Optional[str] = ..., factor_ms: _Optional[float] = ...) -> None: ...

class PhantomSource(_message.Message):
    __slots__ = ["vertices", "without_bones"]
    VERTICES_FIELD_NUMBER: _ClassVar[int]
    WITHOUT_BONES_FIELD_NUMBER: _ClassVar[int]
    vertices: int
    without_bones: bool
    def __init__(self, vertices: _Optional[int] = ..., without_bones: bool = ...) -> None: ...

class PoseUpdate(_message.Message):
    __slots__ = ["angles", "client_timestamp_ns", "root", "rotations", "sequence", "tools"]
    ANGLES_FIELD_NUMBER: _ClassVar[int]
    CLIENT_TIMESTAMP_NS_FIELD_NUMBER: _ClassVar[int]
    ROOT_FIELD_NUMBER: _ClassVar[int]
    ROTATIONS_FIELD_NUMBER: _ClassVar[int]
    SEQUENCE_FIELD_NUMBER: _ClassVar[int]
    TOOLS_FIELD_NUMBER: _ClassVar[int]
    angles: _containers.RepeatedCompositeFieldContainer[JointAngle]
    client_timestamp_ns: int
    root: RootTransform
    rotations: _containers.RepeatedCompositeFieldContainer[JointRotation]
    sequence: int
    tools: _containers.RepeatedCompositeFieldContainer[ToolState]
    def __init__(self, sequence: _Optional[int] = ..., client_timestamp_ns: _Optional[int] = ..., angles: _Optional[_Iterable[_Union[JointAngle, _Mapping]]] = ..., rotations: _Optional[_Iterable[_Union[JointRotation, _Mapping]]] = ..., root: _Optional[_Union[RootTransform, _Mapping]] = ..., tools: _Optional[_Iterable[_Union[ToolState, _Mapping]]] = ...) -> None: ...

class PredictionWeights(_message.Message):
    __slots__ = ["bones", "num_bones", "weights"]
    BONES_FIELD_NUMBER: _ClassVar[int]
    NUM_BONES_FIELD_NUMBER: _ClassVar[int]
    WEIGHTS_FIELD_NUMBER: _ClassVar[int]
    bones: bytes
    num_bones: int
    weights: bytes
    def __init__(self, bones: _Optional[bytes] = ..., weights: _Optional[bytes] = ..., num_bones: _Optional[int] = ...) -> None: ...

class Quaternion(_message.Message):
    __slots__ = ["w", "x", "y", "z"]
    W_FIELD_NUMBER: _ClassVar[int]
    X_FIELD_NUMBER: _ClassVar[int]
    Y_FIELD_NUMBER: _ClassVar[int]
    Z_FIELD_NUMBER: _ClassVar[int]
    w: float
    x: float
    y: float
    z: float
    def __init__(self, w: _Optional[float] = ..., x: _Optional[float] = ..., y: _Optional[float] = ..., z: _Optional[float] = ...) -> None: ...

class QueryContactRequest(_message.Message):
    __slots__ = ["query", "start"]
    QUERY_FIELD_NUMBER: _ClassVar[int]
    START_FIELD_NUMBER: _ClassVar[int]
    query: ContactQuery
    start: ContactQueryStart
    def __init__(self, start: _Optional[_Union[ContactQueryStart, _Mapping]] = ..., query: _Optional[_Union[ContactQuery, _Mapping]] = ...) -> None: ...

class QueryContactResponse(_message.Message):
    __slots__ = ["result", "started"]
    RESULT_FIELD_NUMBER: _ClassVar[int]
    STARTED_FIELD_NUMBER: _ClassVar[int]
    result: ContactResult
    started: ContactQueryStarted
    def __init__(self, started: _Optional[_Union[ContactQueryStarted, _Mapping]] = ..., result: _Optional[_Union[ContactResult, _Mapping]] = ...) -> None: ...

class RegionWeight(_message.Message):
    __slots__ = ["joint", "weight"]
    JOINT_FIELD_NUMBER: _ClassVar[int]
    WEIGHT_FIELD_NUMBER: _ClassVar[int]
    joint: str
    weight: float
    def __init__(self, joint: _Optional[str] = ..., weight: _Optional[float] = ...) -> None: ...

class RootTransform(_message.Message):
    __slots__ = ["rotation", "translation"]
    ROTATION_FIELD_NUMBER: _ClassVar[int]
    TRANSLATION_FIELD_NUMBER: _ClassVar[int]
    rotation: Quaternion
    translation: Vector3
    def __init__(self, translation: _Optional[_Union[Vector3, _Mapping]] = ..., rotation: _Optional[_Union[Quaternion, _Mapping]] = ...) -> None: ...

class StiffnessUpdate(_message.Message):
    __slots__ = ["joint_materials", "region_weights", "vertex_indices", "vertex_weights"]
    JOINT_MATERIALS_FIELD_NUMBER: _ClassVar[int]
    REGION_WEIGHTS_FIELD_NUMBER: _ClassVar[int]
    VERTEX_INDICES_FIELD_NUMBER: _ClassVar[int]
    VERTEX_WEIGHTS_FIELD_NUMBER: _ClassVar[int]
    joint_materials: _containers.RepeatedCompositeFieldContainer[JointMaterialUpdate]
    region_weights: _containers.RepeatedCompositeFieldContainer[RegionWeight]
    vertex_indices: _containers.RepeatedScalarFieldContainer[int]
    vertex_weights: _containers.RepeatedScalarFieldContainer[float]
    def __init__(self, joint_materials: _Optional[_Iterable[_Union[JointMaterialUpdate, _Mapping]]] = ..., region_weights: _Optional[_Iterable[_Union[RegionWeight, _Mapping]]] = ..., vertex_indices: _Optional[_Iterable[int]] = ..., vertex_weights: _Optional[_Iterable[float]] = ...) -> None: ...

class ToolState(_message.Message):
    __slots__ = ["center", "end", "radius", "shape"]
    class Shape(int, metaclass=_enum_type_wrapper.EnumTypeWrapper):
        __slots__ = []
    CENTER_FIELD_NUMBER: _ClassVar[int]
    END_FIELD_NUMBER: _ClassVar[int]
    RADIUS_FIELD_NUMBER: _ClassVar[int]
    SHAPE_CAPSULE: ToolState.Shape
    SHAPE_FIELD_NUMBER: _ClassVar[int]
    SHAPE_SPHERE: ToolState.Shape
    SHAPE_UNSPECIFIED: ToolState.Shape
    center: Vector3
    end: Vector3
    radius: float
    shape: ToolState.Shape
    def __init__(self, shape: _Optional[_Union[ToolState.Shape, str]] = ..., center: _Optional[_Union[Vector3, _Mapping]] = ..., end: _Optional[_Union[Vector3, _Mapping]] = ..., radius: _Optional[float] = ...) -> None: ...

class UnloadMeshRequest(_message.Message):
    __slots__ = ["mesh_id"]
    MESH_ID_FIELD_NUMBER: _ClassVar[int]
    mesh_id: str
    def __init__(self, mesh_id: _Optional[str] = ...) -> None: ...

class UnloadMeshResponse(_message.Message):
    __slots__ = []
    def __init__(self) -> None: ...

class UploadSource(_message.Message):
    __slots__ = ["bone_surfaces", "format", "mesh_size_bytes", "skeleton", "skeleton_format", "skip_gltf_bone_nodes", "weights", "weights_format"]
    BONE_SURFACES_FIELD_NUMBER: _ClassVar[int]
    FORMAT_FIELD_NUMBER: _ClassVar[int]
    MESH_SIZE_BYTES_FIELD_NUMBER: _ClassVar[int]
    SKELETON_FIELD_NUMBER: _ClassVar[int]
    SKELETON_FORMAT_FIELD_NUMBER: _ClassVar[int]
    SKIP_GLTF_BONE_NODES_FIELD_NUMBER: _ClassVar[int]
    WEIGHTS_FIELD_NUMBER: _ClassVar[int]
    WEIGHTS_FORMAT_FIELD_NUMBER: _ClassVar[int]
    bone_surfaces: _containers.RepeatedCompositeFieldContainer[BoneSurfaceUpload]
    format: MeshFormat
    mesh_size_bytes: int
    skeleton: bytes
    skeleton_format: SkeletonFormat
    skip_gltf_bone_nodes: bool
    weights: bytes
    weights_format: SkinWeightsFormat
    def __init__(self, format: _Optional[_Union[MeshFormat, str]] = ..., mesh_size_bytes: _Optional[int] = ..., skeleton_format: _Optional[_Union[SkeletonFormat, str]] = ..., skeleton: _Optional[bytes] = ..., weights_format: _Optional[_Union[SkinWeightsFormat, str]] = ..., weights: _Optional[bytes] = ..., bone_surfaces: _Optional[_Iterable[_Union[BoneSurfaceUpload, _Mapping]]] = ..., skip_gltf_bone_nodes: bool = ...) -> None: ...

class Vector3(_message.Message):
    __slots__ = ["x", "y", "z"]
    X_FIELD_NUMBER: _ClassVar[int]
    Y_FIELD_NUMBER: _ClassVar[int]
    Z_FIELD_NUMBER: _ClassVar[int]
    x: float
    y: float
    z: float
    def __init__(self, x: _Optional[float] = ..., y: _Optional[float] = ..., z: _Optional[float] = ...) -> None: ...

class MeshFormat(int, metaclass=_enum_type_wrapper.EnumTypeWrapper):
    __slots__ = []

class SkeletonFormat(int, metaclass=_enum_type_wrapper.EnumTypeWrapper):
    __slots__ = []

class SkinWeightsFormat(int, metaclass=_enum_type_wrapper.EnumTypeWrapper):
    __slots__ = []

class RotationBlend(int, metaclass=_enum_type_wrapper.EnumTypeWrapper):
    __slots__ = []

class Binding(int, metaclass=_enum_type_wrapper.EnumTypeWrapper):
    __slots__ = []

class FrameEncoding(int, metaclass=_enum_type_wrapper.EnumTypeWrapper):
    __slots__ = []
