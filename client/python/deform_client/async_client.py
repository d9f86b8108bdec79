"""AsyncDeformClient: DeformClient on asyncio (grpc.aio), with the same arguments and answers.

    async with AsyncDeformClient("127.0.0.1:50051") as client:
        mesh = await client.load_phantom(2000, timeout=60)
        async with await client.stream(mesh.mesh_id, encoding="predicted") as stream:
            await stream.send_pose("knee:flexion:90")
            async for frame in stream:
                ...

Every method of DeformClient is a coroutine here (load_phantom, load_files, list_meshes, info,
unload, stream, wait_for_ready, close), with the same keywords, deadlines (`timeout=`, calls.py)
and errors (DeformError); the requests, the summaries and the frame decoding are the blocking
client's own (calls.py, summary.py, stream.py). Make the client inside the event loop that uses
it: a grpc.aio channel belongs to one loop.

AsyncDeformStream: a task reads the responses into a queue, and frames are decoded by whoever
awaits them (next_frame, next_event, `async for`). send_pose / send_stiffness are coroutines
that return once gRPC took the request; they may be awaited from several tasks (writes are
serialized). Ending: close() half-closes and waits for the server to end the stream, cancel()
ends it now and quietly; `async with` closes, or cancels when the block raised. With
stream(reconnect=...) the reading task waits out the backoff and opens the next call as the
blocking stream's reader thread does (stream.py, reconnect.py); sends while the stream is lost
only become the latest pose or stiffness, sent again on the next call.
"""

from __future__ import annotations

import asyncio
import random
import time
from typing import (Any, AsyncIterator, Callable, Iterable, List, Literal, Optional, Sequence,
                    Tuple, Union)

import grpc
import grpc.aio

from . import calls, codec
from .calls import DEFAULT, BoneSurfaceSpec, PathLike, Progress, Timeout
from .channel import DEFAULT_MAX_RECEIVE_MESSAGE_BYTES, Pem, channel_settings
from .client import _env, environment_settings
from .errors import DeformError
from .reconnect import OnReconnect, Reconnect, ReconnectPolicy, is_loss, policy_of
from .stream import Event, Frame, PoseNumbering, event_from
from .stubs import grpc_stubs, pb
from .summary import MeshInfo, MeshSummary
from .tools import ToolSpec

_END = object()


class AsyncDeformStream:
    def __init__(self, call: grpc.aio.StreamStreamCall, decoder: codec.FrameDecoder,
                 reopen: Optional[Callable[[], grpc.aio.StreamStreamCall]] = None,
                 start: Optional[pb.DeformStart] = None,
                 reconnect: Optional[ReconnectPolicy] = None,
                 on_reconnect: Optional[OnReconnect] = None):
        """call: a Deform call whose DeformStart was written; decoder: the mesh's; with
        `reconnect` (a ReconnectPolicy), reopen() makes the next call, to which `start` is
        written again; on_reconnect: reconnect.OnReconnect."""
        self._call = call
        self._decoder = decoder
        self._reopen = reopen
        self._start = start
        self._policy = reconnect if reopen is not None and start is not None else None
        self._on_reconnect = on_reconnect
        self._jitter = random.Random()
        self._wake = asyncio.Event()  # set by close() and cancel(): ends a backoff's wait
        self._events: asyncio.Queue = asyncio.Queue()
        self._write_lock = asyncio.Lock()
        self._numbering = PoseNumbering()
        self._closing = False
        self._cancelled = False
        self._ended = False
        self._lost = False
        self._latest_pose: Optional[pb.DeformRequest] = None
        self._latest_stiffness: Optional[pb.DeformRequest] = None
        self._attempts = 0    # re-opened calls since the last frame
        self._lost_at = 0.0   # loop time of the loss, the first since the last frame
        self.reconnects = 0   # calls re-opened after a loss (reconnect.py), in all
        self.notices: List[pb.Notice] = []  # every Notice taken so far
        self._reader = asyncio.get_running_loop().create_task(self._read())

    async def _read(self) -> None:
        while True:
            outcome: object = _END
            try:
                while True:
                    response = await self._call.read()
                    if response is grpc.aio.EOF:
                        break
                    if response.HasField("frame"):
                        self._attempts = 0
                    self._events.put_nowait(response)
            except asyncio.CancelledError:
                pass
            except grpc.RpcError as error:
                if not (self._cancelled and error.code() == grpc.StatusCode.CANCELLED):
                    outcome = DeformError.from_rpc_error(error)
            if isinstance(outcome, DeformError) and self._policy is not None and \
                    is_loss(outcome, self._cancelled):
                self._lost = True
                outcome = await self._reconnect(self._policy, outcome)
                if outcome is None:
                    continue
            self._events.put_nowait(outcome)
            return

    async def _reconnect(self, policy: ReconnectPolicy, loss: DeformError) -> object:
        """Waits out the backoff and opens the next call (None), or returns what ends the stream
        instead (a DeformError, or _END once the caller cancelled)."""
        assert self._reopen is not None and self._start is not None
        loop = asyncio.get_running_loop()
        if self._attempts == 0:
            self._lost_at = loop.time()
        while True:
            if self._cancelled:
                return _END
            if self._closing:
                return loss
            if loop.time() - self._lost_at >= policy.give_up_after:
                return loss
            self._attempts += 1
            try:
                await asyncio.wait_for(self._wake.wait(),
                                       policy.delay(self._attempts, loss.retry_delay,
                                                    self._jitter))
                continue  # closed or cancelled meanwhile
            except asyncio.TimeoutError:
                pass
            async with self._write_lock:
                if self._cancelled or self._closing:
                    continue
                self._call = self._reopen()
                self._lost = False
                try:
                    for request in (pb.DeformRequest(start=self._start), self._latest_pose,
                                    self._latest_stiffness):
                        if request is not None:
                            await self._call.write(request)
                except (grpc.RpcError, asyncio.InvalidStateError):
                    pass  # this call failed already: reading it says how
            self.reconnects += 1
            if self._on_reconnect is not None:
                self._on_reconnect(loss, self._attempts)
            return None

    # Sending.

    async def _write(self, request: pb.DeformRequest) -> None:
        if self._lost:
            return  # the next call sends the latest pose and stiffness
        try:
            await self._call.write(request)
        except grpc.RpcError as error:
            if self._policy is not None and is_loss(DeformError.from_rpc_error(error),
                                                    self._cancelled):
                return  # the reading task reconnects
            raise DeformError.from_rpc_error(error) from None
        except asyncio.InvalidStateError:
            if self._policy is not None and not (self._closing or self._cancelled):
                return
            raise RuntimeError("the stream is closed") from None

    def _check_open(self) -> None:
        if self._closing or self._cancelled or self._ended:
            raise RuntimeError("the stream is closed")

    async def send_pose(self, pose: object, sequence: Optional[int] = None,
                        tools: Optional[ToolSpec] = None) -> int:
        """As DeformStream.send_pose: returns the pose's sequence number; RuntimeError once the
        stream is closed or ended; ValueError for a malformed pose or tool."""
        async with self._write_lock:
            self._check_open()
            request, number = self._numbering.request(pose, sequence, tools)
            self._latest_pose = request
            await self._write(request)
            return number

    async def send_stiffness(self, stiffness: pb.StiffnessUpdate) -> None:
        async with self._write_lock:
            self._check_open()
            self._latest_stiffness = pb.DeformRequest(stiffness=stiffness)
            await self._write(self._latest_stiffness)

    # Receiving.

    async def next_event(self, timeout: Optional[float] = None) -> Optional[Event]:
        """The next Frame or Notice, or None once the stream has ended well. Raises DeformError
        when it failed, TimeoutError after `timeout` seconds without an event."""
        if self._ended:
            return None
        try:
            event = await asyncio.wait_for(self._events.get(), timeout)
        except asyncio.TimeoutError:
            raise TimeoutError(f"no frame or notice within {timeout} s") from None
        if event is _END:
            self._ended = True
            return None
        if isinstance(event, DeformError):
            self._ended = True
            raise event
        try:
            return event_from(event, self._decoder, self.notices)
        except DeformError:
            self._ended = True
            self.cancel()
            raise

    async def next_frame(self, timeout: Optional[float] = None) -> Optional[Frame]:
        """The next Frame (notices go to self.notices), or None once the stream has ended."""
        while True:
            event = await self.next_event(timeout)
            if event is None or isinstance(event, Frame):
                return event

    def __aiter__(self) -> AsyncIterator[Frame]:
        return self._frames()

    async def _frames(self) -> AsyncIterator[Frame]:
        while True:
            frame = await self.next_frame()
            if frame is None:
                return
            yield frame

    async def events(self) -> AsyncIterator[Event]:
        """Frames and Notices until the stream ends."""
        while True:
            event = await self.next_event()
            if event is None:
                return
            yield event

    # Ending.

    async def close(self, timeout: float = 30.0) -> None:
        """Half-closes, then waits up to `timeout` s for the server to end the stream, dropping
        frames not taken yet. Raises DeformError if the stream failed, TimeoutError (after
        cancelling the call) if it did not end in time."""
        async with self._write_lock:
            if not self._closing and not self._ended and not self._cancelled:
                self._closing = True
                self._wake.set()
                try:
                    await self._call.done_writing()
                except (grpc.RpcError, asyncio.InvalidStateError):
                    pass  # the call failed: the reader reports why
        loop = asyncio.get_running_loop()
        deadline = loop.time() + timeout
        try:
            while await self.next_event(timeout=max(0.0, deadline - loop.time())) is not None:
                pass
        except TimeoutError:
            self.cancel()
            raise

    def cancel(self) -> None:
        """Cancels the call now; the stream ends quietly."""
        self._cancelled = True
        self._wake.set()
        self._call.cancel()

    async def __aenter__(self) -> "AsyncDeformStream":
        return self

    async def __aexit__(self, exc_type: object, exc: object, traceback: object) -> "Literal[False]":
        if exc_type is None:
            await self.close()
        else:
            self.cancel()
        return False


class AsyncDeformClient:
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
            self._channel = grpc.aio.secure_channel(target, credentials, options=options)
        else:
            self._channel = grpc.aio.insecure_channel(target, options=options)
        self._stub = grpc_stubs.DeformServiceStub(self._channel)
        self._metadata: Sequence[Tuple[str, str]] = calls.metadata(token)
        self._unary_timeout = calls.deadline(unary_timeout, None)
        self._load_timeout = calls.deadline(load_timeout, None)
        self._chunk = upload_chunk_bytes
        self.target = target

    # Connection.

    async def wait_for_ready(self, timeout: float = 10.0) -> bool:
        """True once the channel is connected, False after `timeout` seconds."""
        try:
            await asyncio.wait_for(self._channel.channel_ready(), timeout)
            return True
        except asyncio.TimeoutError:
            return False

    async def close(self) -> None:
        await self._channel.close()

    async def __aenter__(self) -> "AsyncDeformClient":
        return self

    async def __aexit__(self, *exc: object) -> "Literal[False]":
        await self.close()
        return False

    # Loading.

    async def load_phantom(self, vertices: int = 0, *, name: str = "phantom",
                           options: Optional[pb.MethodOptions] = None,
                           progress: Optional[Progress] = None, bones: bool = True,
                           timeout: Timeout = DEFAULT) -> MeshSummary:
        """As DeformClient.load_phantom."""
        return await self._load(calls.phantom_header(vertices, name, options, bones), None,
                                progress, timeout)

    async def load_files(self, mesh: PathLike, skeleton: Optional[PathLike] = None,
                         weights: Optional[PathLike] = None, *, name: Optional[str] = None,
                         options: Optional[pb.MethodOptions] = None,
                         progress: Optional[Progress] = None,
                         bone_surfaces: Iterable[BoneSurfaceSpec] = (),
                         gltf_bone_nodes: bool = True,
                         timeout: Timeout = DEFAULT) -> MeshSummary:
        """As DeformClient.load_files (the files are read before the call starts)."""
        header, mesh_bytes = calls.files_header(mesh, skeleton, weights, name, options,
                                                bone_surfaces, gltf_bone_nodes)
        return await self._load(header, mesh_bytes, progress, timeout)

    async def _load(self, header: pb.LoadMeshHeader, mesh_bytes: Optional[bytes],
                    progress: Optional[Progress], timeout: Timeout) -> MeshSummary:
        answers = calls.LoadAnswers(progress)
        call = self._stub.LoadMesh(calls.load_requests(header, mesh_bytes, self._chunk),
                                   metadata=self._metadata,
                                   timeout=calls.deadline(timeout, self._load_timeout))
        try:
            async for response in call:
                answers.take(response)
        except grpc.RpcError as error:
            raise DeformError.from_rpc_error(error) from None
        return answers.summary()

    # Inspecting.

    async def _unary(self, method: Any, request: Any, timeout: Timeout,
                     metadata: Optional[Sequence[Tuple[str, str]]] = None) -> Any:
        try:
            return await method(request, metadata=self._metadata if metadata is None else metadata,
                                timeout=calls.deadline(timeout, self._unary_timeout))
        except grpc.RpcError as error:
            raise DeformError.from_rpc_error(error) from None

    async def list_meshes(self, *, timeout: Timeout = DEFAULT) -> List[MeshSummary]:
        """The caller's loaded meshes, in the order they were loaded."""
        return calls.summaries(await self._unary(self._stub.ListMeshes, pb.ListMeshesRequest(),
                                                 timeout))

    async def info(self, mesh_id: str, geometry: bool = False, prediction_weights: bool = False,
                   *, timeout: Timeout = DEFAULT) -> MeshInfo:
        """As DeformClient.info (asked again after a RetryInfo's delay within `timeout`)."""
        request = calls.info_request(mesh_id, geometry, prediction_weights)
        metadata = calls.with_mesh_key(self._metadata, mesh_id)
        seconds = calls.deadline(timeout, self._unary_timeout)
        deadline = None if seconds is None else time.monotonic() + seconds
        while True:
            left = None if deadline is None else max(0.0, deadline - time.monotonic())
            try:
                response = await self._unary(self._stub.GetMeshInfo, request, left, metadata)
                return MeshInfo(response, geometry, prediction_weights)
            except DeformError as error:
                if not calls.retries_after(error, deadline):
                    raise
                await asyncio.sleep(error.retry_delay)

    async def unload(self, mesh_id: str, *, timeout: Timeout = DEFAULT) -> None:
        """Unloads a mesh (streams open on it keep it until they end)."""
        await self._unary(self._stub.UnloadMesh, pb.UnloadMeshRequest(mesh_id=mesh_id), timeout,
                          calls.with_mesh_key(self._metadata, mesh_id))

    # Streaming.

    async def stream(self, mesh_id: str, encoding: Union[str, int] = "float32",
                     max_error: float = 0.0, *, timeout: Optional[float] = None,
                     reconnect: Reconnect = False,
                     on_reconnect: Optional[OnReconnect] = None) -> AsyncDeformStream:
        """As DeformClient.stream: asks GetMeshInfo first, then opens the Deform call and sends
        its DeformStart; `reconnect` and `on_reconnect` as there. Returns an AsyncDeformStream."""
        value, predicted = calls.stream_encoding(encoding)
        info = await self.info(mesh_id, geometry=predicted, prediction_weights=predicted)
        start, decoder = calls.stream_start(mesh_id, value, max_error, info)
        metadata = calls.with_mesh_key(self._metadata, mesh_id)
        seconds = calls.deadline(timeout, None)
        deadline = None if seconds is None else time.monotonic() + seconds

        def open_call() -> grpc.aio.StreamStreamCall:  # re-opened calls share the deadline
            left = None if deadline is None else max(0.0, deadline - time.monotonic())
            return self._stub.Deform(metadata=metadata, timeout=left)

        call = open_call()
        try:
            await call.write(pb.DeformRequest(start=start))
        except grpc.RpcError as error:
            raise DeformError.from_rpc_error(error) from None
        return AsyncDeformStream(call, decoder, reopen=open_call, start=start,
                                 reconnect=policy_of(reconnect), on_reconnect=on_reconnect)


def async_client_from_environment(target: Optional[str] = None) -> AsyncDeformClient:
    """client_from_environment's settings for an AsyncDeformClient."""
    return AsyncDeformClient(target or _env("DEFORM_TARGET") or "127.0.0.1:50051",
                             **environment_settings())
