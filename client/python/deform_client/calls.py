"""What the blocking and the asyncio clients share: the requests they send, the deadlines they
put on them, and how they read the answers. Neither client builds a message of its own.

Timeouts: every call takes `timeout=` in seconds. DEFAULT (the default) means the client's own:
`unary_timeout` (30 s) for info, list and unload, `load_timeout` (600 s, a load's time grows
with the mesh) for loads; None means no deadline (what a stream has unless given one). A call
past its deadline fails with DeformError DEADLINE_EXCEEDED.

Routing: every call that names a mesh (info, unload, stream, contact) carries the metadata
MESH_KEY_HEADER with the mesh's id (its content key), as the C++ library's calls do
(client/lib/deform_client.h, kMeshKeyHeader), so that a balancer in front of several servers
sends all of a mesh's calls to the one that holds it (docs/cluster.md).
"""

from __future__ import annotations

import pathlib
import time
from typing import (Callable, Iterable, Iterator, List, Optional, Sequence, Tuple, Union,
                    cast)

import grpc

from . import codec
from .errors import DeformError
from .stubs import pb
from .summary import MeshInfo, MeshSummary

DEFAULT_UNARY_TIMEOUT = 30.0
DEFAULT_LOAD_TIMEOUT = 600.0
DEFAULT_UPLOAD_CHUNK_BYTES = 1 << 20


class _ClientDefault:
    def __repr__(self) -> str:
        return "DEFAULT"


DEFAULT = _ClientDefault()
"""A call's `timeout=` default: the client's unary_timeout or load_timeout."""

Timeout = Union[float, None, _ClientDefault]
Progress = Callable[[str, float], None]
BoneSurfaceSpec = Union[str, Tuple[Union[str, pathlib.Path], Union[int, str]]]
PathLike = Union[str, pathlib.Path]


def deadline(timeout: Timeout, client_default: Optional[float]) -> Optional[float]:
    """The seconds gRPC is given for a call (None: no deadline); ValueError below zero."""
    seconds = client_default if isinstance(timeout, _ClientDefault) else timeout
    if seconds is not None and not seconds >= 0:
        raise ValueError(f"a timeout is a number of seconds >= 0 or None, not {seconds!r}")
    return seconds


MESH_FORMATS = {".obj": pb.MESH_FORMAT_OBJ, ".ply": pb.MESH_FORMAT_PLY,
                ".stl": pb.MESH_FORMAT_STL, ".off": pb.MESH_FORMAT_OFF,
                ".gltf": pb.MESH_FORMAT_GLTF, ".glb": pb.MESH_FORMAT_GLTF}


def _bone_surface_upload(surface: BoneSurfaceSpec) -> pb.BoneSurfaceUpload:
    """A BoneSurfaceUpload from "FILE:BONE" (the first ':' splits) or a (file, bone) pair."""
    if isinstance(surface, str):
        path_text, colon, bone = surface.partition(":")
        if not colon or not path_text or not bone:
            raise ValueError(f"bone surface '{surface}' is not FILE:BONE")
        path = pathlib.Path(path_text)
    else:
        path, bone = pathlib.Path(surface[0]), str(surface[1])
    mesh_format = MESH_FORMATS.get(path.suffix.lower())
    if mesh_format is None or mesh_format == pb.MESH_FORMAT_GLTF:
        raise ValueError(f"unknown bone surface format for '{path}' (.obj .ply .stl .off)")
    return pb.BoneSurfaceUpload(name=path.stem, format=mesh_format, mesh=path.read_bytes(),
                                bone=str(bone))


def phantom_header(vertices: int, name: str, options: Optional[pb.MethodOptions],
                   bones: bool) -> pb.LoadMeshHeader:
    header = pb.LoadMeshHeader(name=name, phantom=pb.PhantomSource(
        vertices=int(vertices), without_bones=not bones))
    if options is not None:
        header.options.CopyFrom(options)
    return header


def files_header(mesh: PathLike, skeleton: Optional[PathLike], weights: Optional[PathLike],
                 name: Optional[str], options: Optional[pb.MethodOptions],
                 bone_surfaces: Iterable[BoneSurfaceSpec],
                 gltf_bone_nodes: bool) -> Tuple[pb.LoadMeshHeader, bytes]:
    """The header of an upload and the mesh file's bytes (read here: FileNotFoundError before the
    server is contacted; ValueError for an unknown format)."""
    mesh = pathlib.Path(mesh)
    mesh_format = MESH_FORMATS.get(mesh.suffix.lower())
    if mesh_format is None:
        raise ValueError(f"unknown mesh format for '{mesh}' (.obj .ply .stl .off, or a "
                         f".gltf/.glb rig)")
    mesh_bytes = mesh.read_bytes()
    upload = pb.UploadSource(format=mesh_format, mesh_size_bytes=len(mesh_bytes))
    if skeleton is not None:
        skeleton = pathlib.Path(skeleton)
        upload.skeleton = skeleton.read_bytes()
        upload.skeleton_format = (pb.SKELETON_FORMAT_TGF if skeleton.suffix.lower() == ".tgf"
                                  else pb.SKELETON_FORMAT_JSON)
    if weights is not None:
        weights = pathlib.Path(weights)
        upload.weights = weights.read_bytes()
        upload.weights_format = (pb.SKIN_WEIGHTS_FORMAT_CSV if weights.suffix.lower() == ".csv"
                                 else pb.SKIN_WEIGHTS_FORMAT_DMAT)
    for surface in bone_surfaces:
        upload.bone_surfaces.append(_bone_surface_upload(surface))
    upload.skip_gltf_bone_nodes = not gltf_bone_nodes
    header = pb.LoadMeshHeader(name=name or mesh.name, upload=upload)
    if options is not None:
        header.options.CopyFrom(options)
    return header, mesh_bytes


def load_requests(header: pb.LoadMeshHeader, mesh_bytes: Optional[bytes],
                  chunk_bytes: int) -> Iterator[pb.LoadMeshRequest]:
    """The LoadMesh request stream: the header, then the mesh file in `chunk_bytes` chunks."""
    yield pb.LoadMeshRequest(header=header)
    if mesh_bytes is not None:
        for offset in range(0, len(mesh_bytes), chunk_bytes):
            yield pb.LoadMeshRequest(chunk=mesh_bytes[offset:offset + chunk_bytes])


class LoadAnswers:
    """Reads LoadMesh's answers: calls `progress(stage, elapsed_ms)` for each, keeps the READY
    summary; summary() raises DeformError(INTERNAL) when the call ended without one."""

    def __init__(self, progress: Optional[Progress]):
        self._progress = progress
        self._summary: Optional[pb.MeshSummary] = None

    def take(self, response: pb.LoadMeshResponse) -> None:
        if self._progress is not None:
            stage = pb.LoadMeshResponse.Stage.Name(response.stage).removeprefix("STAGE_")
            self._progress(stage, response.elapsed_ms)
        if response.stage == pb.LoadMeshResponse.STAGE_READY:
            self._summary = response.mesh

    def summary(self) -> MeshSummary:
        if self._summary is None:
            raise DeformError(grpc.StatusCode.INTERNAL,
                              "LoadMesh ended without a STAGE_READY message")
        return MeshSummary.from_message(self._summary)


def info_request(mesh_id: str, geometry: bool,
                 prediction_weights: bool) -> pb.GetMeshInfoRequest:
    return pb.GetMeshInfoRequest(mesh_id=mesh_id, include_geometry=geometry,
                                 include_prediction_weights=prediction_weights)


def summaries(response: pb.ListMeshesResponse) -> List[MeshSummary]:
    return [MeshSummary.from_message(mesh) for mesh in response.meshes]


def stream_encoding(encoding: Union[str, int]) -> Tuple[int, bool]:
    """The FrameEncoding value and whether its decoder needs the mesh's geometry and prediction
    weights (GetMeshInfo with both) before the stream opens."""
    value = codec.encoding_from_name(encoding)
    return value, value == codec.PREDICTED


def stream_start(mesh_id: str, encoding: int, max_error: float,
                 info: MeshInfo) -> Tuple[pb.DeformStart, codec.FrameDecoder]:
    """The DeformStart message and the decoder of the stream's frames."""
    if encoding == codec.PREDICTED:
        decoder = codec.FrameDecoder(info.summary.vertex_count, info.response.rest_positions,
                                     info.response.prediction_weights)
    else:
        decoder = codec.FrameDecoder(info.summary.vertex_count)
    start = pb.DeformStart(mesh_id=mesh_id, encoding=cast(pb.FrameEncoding, encoding),
                           max_error=max_error)
    return start, decoder


def metadata(token: Optional[str]) -> Sequence[Tuple[str, str]]:
    return (("authorization", f"Bearer {token}"),) if token else ()


MESH_KEY_HEADER = "deform-mesh-key"
_MAX_MESH_KEY_BYTES = 128


def with_mesh_key(base: Sequence[Tuple[str, str]],
                  mesh_id: str) -> Sequence[Tuple[str, str]]:
    """`base` and MESH_KEY_HEADER: mesh_id; `base` alone for an id that is not printable ASCII
    (no space) of at most 128 bytes: such an id is no server's (gRPC would refuse it as a value),
    and the call is answered NOT_FOUND unrouted."""
    if not 0 < len(mesh_id) <= _MAX_MESH_KEY_BYTES or \
            any(not 0x21 <= ord(c) <= 0x7e for c in mesh_id):
        return base
    return (*base, (MESH_KEY_HEADER, mesh_id))


def retries_after(error: DeformError, deadline: Optional[float]) -> bool:
    """Whether a unary call that failed with `error` is asked again after error.retry_delay: an
    UNAVAILABLE with a RetryInfo whose delay ends before `deadline` (time.monotonic(); None: no
    deadline)."""
    return (error.code == grpc.StatusCode.UNAVAILABLE and error.retry_delay > 0 and
            (deadline is None or time.monotonic() + error.retry_delay < deadline))
