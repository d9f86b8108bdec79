"""DeformClient: load meshes into deformd, list, inspect and unload them, open Deform streams.

The Python counterpart of the C++ client library (client/lib/deform_client.h):

- Connection: `target` "host:port". Plaintext by default (deformd serves it on loopback only);
  TLS with `tls=True` or any of `ca` (the CA that signed the server's certificate; None: the
  system's roots), `cert` and `key` (the client's certificate chain and key, both or neither, for
  mutual TLS), `server_name` (the name the server's certificate must carry when it differs from
  the target's host). Each is a file path or the PEM contents as bytes.
- Identity: `token` is sent with every call as the metadata "authorization: Bearer <token>".
- Unary calls (info, list_meshes, unload) carry a deadline of `unary_timeout` seconds (default
  30); loads and streams have none (a load's time grows with the mesh).
- Uploads go as a header and then the mesh file in `upload_chunk_bytes` chunks (default 1 MiB).
- Failures of a call raise DeformError (errors.py) with the gRPC status code (NOT_FOUND for an
  unknown mesh id, UNAUTHENTICATED without a valid token, ...); a missing local file raises
  FileNotFoundError before the server is contacted; bad arguments ValueError.

Thread safety: one DeformClient may be used from several threads (gRPC channels are).
"""

import dataclasses
import os
import pathlib

import grpc
import numpy as np

from . import codec
from .contact import ContactQuery
from .errors import DeformError
from .stream import DeformStream
from .stubs import grpc_stubs, pb

_MESH_FORMATS = {".obj": pb.MESH_FORMAT_OBJ, ".ply": pb.MESH_FORMAT_PLY,
                 ".stl": pb.MESH_FORMAT_STL, ".off": pb.MESH_FORMAT_OFF,
                 ".gltf": pb.MESH_FORMAT_GLTF, ".glb": pb.MESH_FORMAT_GLTF}


@dataclasses.dataclass
class BoneSurface:
    """A bone surface of a loaded mesh (MeshSummary.bone_surfaces) and, with geometry, its rest
    positions ((N, 3) float32) and triangles ((T, 3) uint32)."""
    name: str
    bone: int
    blend_bone: int  # -1: none
    blend: float
    rest_positions: np.ndarray = dataclasses.field(default=None, repr=False)
    triangles: np.ndarray = dataclasses.field(default=None, repr=False)


class MeshInfo:
    """GetMeshInfo's answer: `summary` (MeshSummary), `bone_surfaces` (BoneSurface, in the order
    frames carry their transforms), and when asked for, `rest_positions` ((V, 3) float32),
    `triangles` ((T, 3) uint32), each bone surface's geometry and `prediction_weights`
    (PredictionWeights); None when not asked for. `response` is the GetMeshInfoResponse as
    received."""

    def __init__(self, response, geometry, prediction_weights):
        self.response = response
        self.summary = response.summary
        self.rest_positions = None
        self.triangles = None
        self.prediction_weights = None
        self.bone_surfaces = [BoneSurface(s.name, s.bone, s.blend_bone, s.blend)
                              for s in response.summary.bone_surfaces]
        if geometry:
            self.rest_positions = codec.decode_float32(response.rest_positions,
                                                       response.summary.vertex_count)
            self.triangles = np.frombuffer(response.triangles, dtype="<u4").astype(
                np.uint32).reshape(-1, 3)
            for surface, shape in zip(self.bone_surfaces, response.bone_surfaces):
                surface.rest_positions = codec.decode_float32(
                    shape.rest_positions, len(shape.rest_positions) // 12)
                surface.triangles = np.frombuffer(shape.triangles, dtype="<u4").astype(
                    np.uint32).reshape(-1, 3)
        if prediction_weights:
            self.prediction_weights = response.prediction_weights


def _pem(value):
    if value is None:
        return None
    if isinstance(value, bytes):
        return value
    return pathlib.Path(value).read_bytes()


def _bone_surface_upload(surface):
    """A BoneSurfaceUpload from "FILE:BONE" (the first ':' splits) or a (file, bone) pair."""
    if isinstance(surface, str):
        path, colon, bone = surface.partition(":")
        if not colon or not path or not bone:
            raise ValueError(f"bone surface '{surface}' is not FILE:BONE")
    else:
        path, bone = surface
    path = pathlib.Path(path)
    mesh_format = _MESH_FORMATS.get(path.suffix.lower())
    if mesh_format is None or mesh_format == pb.MESH_FORMAT_GLTF:
        raise ValueError(f"unknown bone surface format for '{path}' (.obj .ply .stl .off)")
    return pb.BoneSurfaceUpload(name=path.stem, format=mesh_format, mesh=path.read_bytes(),
                                bone=str(bone))


def _stage_name(stage):
    return pb.LoadMeshResponse.Stage.Name(stage).removeprefix("STAGE_")


class DeformClient:
    def __init__(self, target="127.0.0.1:50051", *, tls=False, ca=None, cert=None, key=None,
                 server_name=None, token=None, unary_timeout=30.0,
                 max_receive_message_bytes=256 << 20, upload_chunk_bytes=1 << 20):
        if (cert is None) != (key is None):
            raise ValueError("a client certificate needs its key and a key its certificate")
        if upload_chunk_bytes < 1:
            raise ValueError("upload_chunk_bytes must be at least 1")
        options = [("grpc.max_receive_message_length", max_receive_message_bytes),
                   ("grpc.max_send_message_length", -1)]
        if tls or ca is not None or cert is not None:
            credentials = grpc.ssl_channel_credentials(root_certificates=_pem(ca),
                                                       private_key=_pem(key),
                                                       certificate_chain=_pem(cert))
            if server_name:
                options.append(("grpc.ssl_target_name_override", server_name))
            self._channel = grpc.secure_channel(target, credentials, options=options)
        else:
            self._channel = grpc.insecure_channel(target, options=options)
        self._stub = grpc_stubs.DeformServiceStub(self._channel)
        self._metadata = (("authorization", f"Bearer {token}"),) if token else ()
        self._unary_timeout = unary_timeout
        self._chunk = upload_chunk_bytes
        self.target = target

    # Connection.

    def wait_for_ready(self, timeout=10.0):
        """True once the channel is connected, False after `timeout` seconds."""
        try:
            grpc.channel_ready_future(self._channel).result(timeout=timeout)
            return True
        except grpc.FutureTimeoutError:
            return False

    def close(self):
        self._channel.close()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()
        return False

    # Loading.

    def load_phantom(self, vertices=0, *, name="phantom", options=None, progress=None,
                     bones=True):
        """Loads the built-in knee phantom of about `vertices` vertices (0: the default, about
        2,000), with its femur, tibia and patella unless `bones` is False. `options`: a
        MethodOptions message (its `constraints`: pb.Constraints(contacts=..., keep_volume=...,
        contact_margin=...)). `progress(stage, elapsed_ms)` is called for every stage (RECEIVED,
        VALIDATED, WEIGHTS, FACTORISED, READY). Returns the MeshSummary."""
        header = pb.LoadMeshHeader(name=name, phantom=pb.PhantomSource(
            vertices=int(vertices), without_bones=not bones))
        if options is not None:
            header.options.CopyFrom(options)
        return self._load(header, None, progress)

    def load_files(self, mesh, skeleton=None, weights=None, *, name=None, options=None,
                   progress=None, bone_surfaces=(), gltf_bone_nodes=True):
        """Uploads a mesh file (.obj .ply .stl .off, or a .gltf/.glb rig that carries skeleton and
        weights: then neither is given) with its skeleton (.tgf, else the project's JSON) and
        optionally the rig's skinning weights (.csv, else DMAT). `bone_surfaces`: closed meshes
        inside the skin (.obj .ply .stl .off), each "FILE:BONE" or a (file, bone) pair, BONE a
        bone index, "HEAD-TAIL" or the joint the bone starts at; named after their files. A glTF
        rig's own bone surfaces (unskinned mesh nodes under its joints that are bones) come first;
        `gltf_bone_nodes=False` leaves them out. Returns the MeshSummary."""
        mesh = pathlib.Path(mesh)
        mesh_format = _MESH_FORMATS.get(mesh.suffix.lower())
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
        return self._load(header, mesh_bytes, progress)

    def _load(self, header, mesh_bytes, progress):
        def requests():
            yield pb.LoadMeshRequest(header=header)
            if mesh_bytes is not None:
                for offset in range(0, len(mesh_bytes), self._chunk):
                    yield pb.LoadMeshRequest(chunk=mesh_bytes[offset:offset + self._chunk])

        summary = None
        try:
            for response in self._stub.LoadMesh(requests(), metadata=self._metadata):
                if progress is not None:
                    progress(_stage_name(response.stage), response.elapsed_ms)
                if response.stage == pb.LoadMeshResponse.STAGE_READY:
                    summary = response.mesh
        except grpc.RpcError as error:
            raise DeformError.from_rpc_error(error) from None
        if summary is None:
            raise DeformError(grpc.StatusCode.INTERNAL,
                              "LoadMesh ended without a STAGE_READY message")
        return summary

    # Inspecting.

    def _unary(self, method, request):
        try:
            return method(request, metadata=self._metadata, timeout=self._unary_timeout)
        except grpc.RpcError as error:
            raise DeformError.from_rpc_error(error) from None

    def list_meshes(self):
        """The caller's loaded meshes (MeshSummary messages), in the order they were loaded."""
        return list(self._unary(self._stub.ListMeshes, pb.ListMeshesRequest()).meshes)

    def info(self, mesh_id, geometry=False, prediction_weights=False):
        """A mesh's MeshInfo; with `geometry` its rest positions and triangles, with
        `prediction_weights` what predicted frames are decoded with."""
        request = pb.GetMeshInfoRequest(mesh_id=mesh_id, include_geometry=geometry,
                                        include_prediction_weights=prediction_weights)
        return MeshInfo(self._unary(self._stub.GetMeshInfo, request), geometry,
                        prediction_weights)

    def unload(self, mesh_id):
        """Unloads a mesh (streams open on it keep it until they end)."""
        self._unary(self._stub.UnloadMesh, pb.UnloadMeshRequest(mesh_id=mesh_id))

    # Streaming.

    def stream(self, mesh_id, encoding="float32", max_error=0.0):
        """Opens a Deform stream on `mesh_id` whose frames travel in `encoding` (float32,
        quantized or predicted; max_error: predicted frames' largest error as a fraction of the
        bounding-box diagonal, 0 = the server's default 5e-5, kDefaultPredictedMaxError in
        server/core/codec/frame_codec.h). Asks GetMeshInfo first for what the decoder needs
        (which also raises NOT_FOUND for an unknown id). Returns a DeformStream (stream.py)."""
        encoding = codec.encoding_from_name(encoding)
        predicted = encoding == codec.PREDICTED
        info = self.info(mesh_id, geometry=predicted, prediction_weights=predicted)
        if predicted:
            decoder = codec.FrameDecoder(info.summary.vertex_count,
                                         info.response.rest_positions,
                                         info.response.prediction_weights)
        else:
            decoder = codec.FrameDecoder(info.summary.vertex_count)
        start = pb.DeformStart(mesh_id=mesh_id, encoding=encoding, max_error=max_error)
        return DeformStream(self._stub, start, self._metadata, decoder)

    def contact(self, mesh_id, deform_stream_id=0, stiffness=0.0):
        """Opens a QueryContact stream on `mesh_id` (contact.py) against the latest frame of the
        Deform stream `deform_stream_id` (a frame's message.stream_id; the same tenant's) or, with
        0, the rest pose; `stiffness` of the force model, 0 = 100. Waits for the server's answer:
        DeformError NOT_FOUND for an unknown mesh or stream."""
        start = pb.ContactQueryStart(mesh_id=mesh_id, deform_stream_id=deform_stream_id,
                                     stiffness=stiffness)
        return ContactQuery(self._stub, start, self._metadata)


def client_from_environment(target=None):
    """A DeformClient configured as the command-line clients are: DEFORM_TARGET (default
    127.0.0.1:50051), DEFORM_TLS ("1"), DEFORM_TLS_CA, DEFORM_TLS_CERT, DEFORM_TLS_KEY,
    DEFORM_TLS_SERVER_NAME and DEFORM_TOKEN."""
    def env(name):
        return os.environ.get(name) or None

    return DeformClient(target or env("DEFORM_TARGET") or "127.0.0.1:50051",
                        tls=(env("DEFORM_TLS") or "").lower() in ("1", "true", "yes", "on"),
                        ca=env("DEFORM_TLS_CA"), cert=env("DEFORM_TLS_CERT"),
                        key=env("DEFORM_TLS_KEY"), server_name=env("DEFORM_TLS_SERVER_NAME"),
                        token=env("DEFORM_TOKEN"))
