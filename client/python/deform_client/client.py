"""DeformClient: load meshes into deformd, list, inspect and unload them, open Deform streams.

The Python counterpart of the C++ client library (client/lib/deform_client.h):

- Connection: `target` "host:port". Plaintext by default (deformd serves it on loopback only);
  TLS with `tls=True` or any of `ca`, `cert`, `key`, `server_name` (channel.py).
- Identity: `token` is sent with every call as the metadata "authorization: Bearer <token>".
- Clusters (docs/cluster.md): the calls that name a mesh also send its id as the metadata
  "deform-mesh-key" (calls.MESH_KEY_HEADER), which a balancer routes on; info() asks again when a
  replica answers UNAVAILABLE with a RetryInfo (it is building the mesh), within its deadline;
  stream(reconnect=True) survives the loss of its server (reconnect.py).
- Deadlines: every call takes `timeout=` (calls.py): by default `unary_timeout` seconds (30) for
  info, list_meshes and unload, `load_timeout` (600) for loads, none for a stream; None: none.
  A call past its deadline raises DeformError DEADLINE_EXCEEDED.
- Answers: loads and list_meshes give MeshSummary objects, info a MeshInfo (summary.py), each
  keeping the protobuf message it wraps.
- Uploads go as a header and then the mesh file in `upload_chunk_bytes` chunks (default 1 MiB).
- Failures of a call raise DeformError (errors.py) with the gRPC status code (NOT_FOUND for an
  unknown mesh id, UNAUTHENTICATED without a valid token, ...); a missing local file raises
  FileNotFoundError before the server is contacted; bad arguments ValueError.

Thread safety: one DeformClient may be used from several threads (gRPC channels are).
async_client.py is the same client on asyncio.
"""

from __future__ import annotations

import os
import time
from typing import Any, Iterable, List, Literal, Optional, Sequence, Tuple, Union

import grpc

from . import calls
from .calls import DEFAULT, BoneSurfaceSpec, PathLike, Progress, Timeout
from .channel import DEFAULT_MAX_RECEIVE_MESSAGE_BYTES, Pem, channel_settings
from .contact import ContactQuery
from .errors import DeformError
from .reconnect import OnReconnect, Reconnect, policy_of
from .stream import DeformStream
from .stubs import grpc_stubs, pb
from .summary import BoneSurface, MeshInfo, MeshSummary

__all__ = ["BoneSurface", "DeformClient", "MeshInfo", "MeshSummary", "client_from_environment"]


class DeformClient:
    def __init__(self, target: str = "127.0.0.1:50051", *, tls: bool = False, ca: Pem = None,
                 cert: Pem = None, key: Pem = None, server_name: Optional[str] = None,
                 token: Optional[str] = None,
                 unary_timeout: Optional[float] = calls.DEFAULT_UNARY_TIMEOUT,
                 load_timeout: Optional[float] = calls.DEFAULT_LOAD_TIMEOUT,
                 max_receive_message_bytes: int = DEFAULT_MAX_RECEIVE_MESSAGE_BYTES,
                 upload_chunk_bytes: int = calls.DEFAULT_UPLOAD_CHUNK_BYTES):
        if upload_chunk_bytes < 1:
            raise ValueError("upload_chunk_bytes must be at least 1")
        credentials, options = channel_settings(tls, ca, cert, key, server_name,
                                                max_receive_message_bytes)
        if credentials is not None:
            self._channel = grpc.secure_channel(target, credentials, options=options)
        else:
            self._channel = grpc.insecure_channel(target, options=options)
        self._stub = grpc_stubs.DeformServiceStub(self._channel)
        self._metadata = calls.metadata(token)
        self._unary_timeout = calls.deadline(unary_timeout, None)
        self._load_timeout = calls.deadline(load_timeout, None)
        self._chunk = upload_chunk_bytes
        self.target = target

    # Connection.

    def wait_for_ready(self, timeout: float = 10.0) -> bool:
        """True once the channel is connected, False after `timeout` seconds."""
        try:
            grpc.channel_ready_future(self._channel).result(timeout=timeout)
            return True
        except grpc.FutureTimeoutError:
            return False

    def close(self) -> None:
        self._channel.close()

    def __enter__(self) -> "DeformClient":
        return self

    def __exit__(self, *exc: object) -> "Literal[False]":
        self.close()
        return False

    # Loading.

    def load_phantom(self, vertices: int = 0, *, name: str = "phantom",
                     options: Optional[pb.MethodOptions] = None,
                     progress: Optional[Progress] = None, bones: bool = True,
                     timeout: Timeout = DEFAULT) -> MeshSummary:
        """Loads the built-in knee phantom of about `vertices` vertices (0: the default, about
        2,000), with its femur, tibia and patella unless `bones` is False. `options`: a
        MethodOptions message (its `constraints`: pb.Constraints(contacts=..., keep_volume=...,
        contact_margin=...)). `progress(stage, elapsed_ms)` is called for every stage (RECEIVED,
        VALIDATED, WEIGHTS, FACTORISED, READY). `timeout`: seconds for the whole load (default
        the client's load_timeout). Returns the MeshSummary."""
        return self._load(calls.phantom_header(vertices, name, options, bones), None, progress,
                          timeout)

    def load_files(self, mesh: PathLike, skeleton: Optional[PathLike] = None,
                   weights: Optional[PathLike] = None, *, name: Optional[str] = None,
                   options: Optional[pb.MethodOptions] = None,
                   progress: Optional[Progress] = None,
                   bone_surfaces: Iterable[BoneSurfaceSpec] = (), gltf_bone_nodes: bool = True,
                   timeout: Timeout = DEFAULT) -> MeshSummary:
        """Uploads a mesh file (.obj .ply .stl .off, or a .gltf/.glb rig that carries skeleton and
        weights: then neither is given) with its skeleton (.tgf, else the project's JSON) and
        optionally the rig's skinning weights (.csv, else DMAT). `bone_surfaces`: closed meshes
        inside the skin (.obj .ply .stl .off), each "FILE:BONE" or a (file, bone) pair, BONE a
        bone index, "HEAD-TAIL" or the joint the bone starts at; named after their files. A glTF
        rig's own bone surfaces (unskinned mesh nodes under its joints that are bones) come first;
        `gltf_bone_nodes=False` leaves them out. `timeout` as for load_phantom. Returns the
        MeshSummary."""
        header, mesh_bytes = calls.files_header(mesh, skeleton, weights, name, options,
                                                bone_surfaces, gltf_bone_nodes)
        return self._load(header, mesh_bytes, progress, timeout)

    def _load(self, header: pb.LoadMeshHeader, mesh_bytes: Optional[bytes],
              progress: Optional[Progress], timeout: Timeout) -> MeshSummary:
        answers = calls.LoadAnswers(progress)
        try:
            for response in self._stub.LoadMesh(
                    calls.load_requests(header, mesh_bytes, self._chunk),
                    metadata=self._metadata, timeout=calls.deadline(timeout, self._load_timeout)):
                answers.take(response)
        except grpc.RpcError as error:
            raise DeformError.from_rpc_error(error) from None
        return answers.summary()

    # Inspecting.

    def _unary(self, method: Any, request: Any, timeout: Timeout,
               metadata: Optional[Sequence[Tuple[str, str]]] = None) -> Any:
        try:
            return method(request, metadata=self._metadata if metadata is None else metadata,
                          timeout=calls.deadline(timeout, self._unary_timeout))
        except grpc.RpcError as error:
            raise DeformError.from_rpc_error(error) from None

    def list_meshes(self, *, timeout: Timeout = DEFAULT) -> List[MeshSummary]:
        """The caller's loaded meshes, in the order they were loaded."""
        return calls.summaries(self._unary(self._stub.ListMeshes, pb.ListMeshesRequest(),
                                           timeout))

    def info(self, mesh_id: str, geometry: bool = False, prediction_weights: bool = False, *,
             timeout: Timeout = DEFAULT) -> MeshInfo:
        """A mesh's MeshInfo; with `geometry` its rest positions and triangles, with
        `prediction_weights` what predicted frames are decoded with. A server that answers
        UNAVAILABLE with a RetryInfo (a replica building the mesh from a shared store) is asked
        again after the delay it gives, while that ends within `timeout` (None: always)."""
        request = calls.info_request(mesh_id, geometry, prediction_weights)
        metadata = calls.with_mesh_key(self._metadata, mesh_id)
        seconds = calls.deadline(timeout, self._unary_timeout)
        deadline = None if seconds is None else time.monotonic() + seconds
        while True:
            left = None if deadline is None else max(0.0, deadline - time.monotonic())
            try:
                response = self._unary(self._stub.GetMeshInfo, request, left, metadata)
                return MeshInfo(response, geometry, prediction_weights)
            except DeformError as error:
                if not calls.retries_after(error, deadline):
                    raise
                time.sleep(error.retry_delay)

    def unload(self, mesh_id: str, *, timeout: Timeout = DEFAULT) -> None:
        """Unloads a mesh (streams open on it keep it until they end)."""
        self._unary(self._stub.UnloadMesh, pb.UnloadMeshRequest(mesh_id=mesh_id), timeout,
                    calls.with_mesh_key(self._metadata, mesh_id))

    # Streaming.

    def stream(self, mesh_id: str, encoding: Union[str, int] = "float32",
               max_error: float = 0.0, *, timeout: Optional[float] = None,
               reconnect: Reconnect = False,
               on_reconnect: Optional[OnReconnect] = None) -> DeformStream:
        """Opens a Deform stream on `mesh_id` whose frames travel in `encoding` (float32,
        quantized or predicted; max_error: predicted frames' largest error as a fraction of the
        bounding-box diagonal, 0 = the server's default 5e-5, kDefaultPredictedMaxError in
        server/core/codec/frame_codec.h). Asks GetMeshInfo first for what the decoder needs
        (which also raises NOT_FOUND for an unknown id; within the unary timeout). `timeout`:
        the stream's deadline in seconds (default None: none; past it the stream fails with
        DEADLINE_EXCEEDED). `reconnect`: True or a ReconnectPolicy (reconnect.py) for a stream
        that survives the loss of its server, `on_reconnect(loss, attempt)` hearing of each
        re-opened call (also counted in the stream's `reconnects`); default off. Returns a
        DeformStream (stream.py)."""
        value, predicted = calls.stream_encoding(encoding)
        info = self.info(mesh_id, geometry=predicted, prediction_weights=predicted)
        start, decoder = calls.stream_start(mesh_id, value, max_error, info)
        return DeformStream(self._stub, start, calls.with_mesh_key(self._metadata, mesh_id),
                            decoder, timeout=calls.deadline(timeout, None),
                            reconnect=policy_of(reconnect), on_reconnect=on_reconnect)

    def contact(self, mesh_id: str, deform_stream_id: int = 0,
                stiffness: float = 0.0) -> ContactQuery:
        """Opens a QueryContact stream on `mesh_id` (contact.py) against the latest frame of the
        Deform stream `deform_stream_id` (a frame's message.stream_id; the same tenant's) or, with
        0, the rest pose; `stiffness` of the force model, 0 = 100. Waits for the server's answer:
        DeformError NOT_FOUND for an unknown mesh or stream."""
        start = pb.ContactQueryStart(mesh_id=mesh_id, deform_stream_id=deform_stream_id,
                                     stiffness=stiffness)
        return ContactQuery(self._stub, start, calls.with_mesh_key(self._metadata, mesh_id))


def client_from_environment(target: Optional[str] = None) -> DeformClient:
    """A DeformClient configured as the command-line clients are: DEFORM_TARGET (default
    127.0.0.1:50051), DEFORM_TLS ("1"), DEFORM_TLS_CA, DEFORM_TLS_CERT, DEFORM_TLS_KEY,
    DEFORM_TLS_SERVER_NAME and DEFORM_TOKEN."""
    return DeformClient(target or _env("DEFORM_TARGET") or "127.0.0.1:50051",
                        **environment_settings())


def _env(name: str) -> Optional[str]:
    return os.environ.get(name) or None


def environment_settings() -> dict:
    """The connection keywords (tls, ca, cert, key, server_name, token) from DEFORM_TLS*,
    DEFORM_TOKEN: what client_from_environment gives either client."""
    return dict(tls=(_env("DEFORM_TLS") or "").lower() in ("1", "true", "yes", "on"),
                ca=_env("DEFORM_TLS_CA"), cert=_env("DEFORM_TLS_CERT"),
                key=_env("DEFORM_TLS_KEY"), server_name=_env("DEFORM_TLS_SERVER_NAME"),
                token=_env("DEFORM_TOKEN"))
