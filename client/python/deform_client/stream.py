"""DeformStream: one Deform call. Poses go in, frames come out as numpy arrays.

Made by DeformClient.stream(). Requests are sent in order (the server answers the newest pose
when poses come faster than it solves, and reports the others in Frame.skipped_poses). A
background thread reads the responses into a queue; frames are decoded by whoever takes them
(next_frame, iteration), so decoding costs the reader's thread, not gRPC's.

Thread safety: send_pose / send_stiffness / close / cancel may be called from any thread; take
frames (next_frame, next_event, iteration) from one thread at a time.

Errors: the call's failure (NOT_FOUND for an unknown mesh id, INVALID_ARGUMENT for a bad start,
UNAVAILABLE when the server shuts down, ...) is raised as DeformError by whatever takes the next
event after it; a frame that does not decode cancels the call and raises DeformError(INTERNAL)
naming the problem. A cancel() by the caller ends the stream quietly. A stream opened with a
deadline (DeformClient.stream(timeout=)) fails with DEADLINE_EXCEEDED past it.

Reconnecting (DeformClient.stream(reconnect=...), reconnect.py): the reader thread itself waits
out the backoff and opens the next call, which starts with the same DeformStart and the latest
pose and stiffness update; its frames follow in the same queue. Sends while the stream is lost
only become the latest pose or stiffness. The frames' decoder is kept: the same mesh id is the
same content on every server (docs/cluster.md). A close() while the stream is lost ends it with
the loss's DeformError, as without reconnecting; a cancel() ends it quietly.

event_from and PoseNumbering are shared with the asyncio stream (async_client.py).
"""

from __future__ import annotations

import dataclasses
import queue
import random
import threading
import time
from typing import Any, Iterator, List, Literal, Optional, Sequence, Tuple, Union

import grpc
import numpy as np

from . import codec
from .errors import DeformError
from .poses import pose_update
from .reconnect import OnReconnect, ReconnectPolicy, is_loss
from .stubs import pb
from .tools import ToolSpec, tool_states

_END = object()
Event = Union["Frame", pb.Notice]


@dataclasses.dataclass
class Frame:
    """One deformed frame. positions: (V, 3) float32, model units, the mesh's vertex order."""
    sequence: int              # the pose answered
    positions: np.ndarray = dataclasses.field(repr=False)
    encoding: str              # how it travelled: float32, quantized or predicted
    max_error: float           # the stated largest per-coordinate error (0 for float32)
    wire_bytes: int            # bytes of positions as they travelled
    decode_ms: float           # this client's decoding time
    skipped_poses: int
    clamped_angles: int
    mesh_unloaded: bool
    stiffness_version: int
    client_timestamp_ns: int
    message: pb.DeformFrame = dataclasses.field(repr=False)  # the DeformFrame as received
    # The bone surfaces' rigid motions, (S, 3, 4) float32 [R | t] (posed = R rest + t), in the
    # order of MeshInfo.bone_surfaces; (0, 3, 4) for a mesh without bones.
    bone_transforms: Optional[np.ndarray] = dataclasses.field(default=None, repr=False)
    # What the constraints did (FrameConstraints: penetrating_before, penetrating_after,
    # max_depth_after, unresolved, contacts, volume_change), or None for a mesh without them.
    constraints: Optional[pb.FrameConstraints] = None


def _frame_from(message: pb.DeformFrame, decoder: codec.FrameDecoder) -> Frame:
    started = time.perf_counter()
    positions = decoder.decode(message)
    decode_ms = (time.perf_counter() - started) * 1e3
    if message.HasField("encoded"):
        encoded = message.encoded
        encoding, max_error, wire_bytes = (codec.ENCODING_NAMES.get(encoded.encoding, "unknown"),
                                           encoded.max_error, len(encoded.data))
    else:
        encoding, max_error, wire_bytes = "float32", 0.0, len(message.positions)
    return Frame(sequence=message.sequence, positions=positions, encoding=encoding,
                 max_error=max_error, wire_bytes=wire_bytes, decode_ms=decode_ms,
                 skipped_poses=message.skipped_poses, clamped_angles=message.clamped_angles,
                 mesh_unloaded=message.mesh_unloaded, stiffness_version=message.stiffness_version,
                 client_timestamp_ns=message.client_timestamp_ns, message=message,
                 bone_transforms=decode_bone_transforms(message.bone_transforms),
                 constraints=message.constraints if message.HasField("constraints") else None)


def decode_bone_transforms(data: bytes) -> np.ndarray:
    """DeformFrame.bone_transforms (12 float32 per surface: row-major R, then t) as an (S, 3, 4)
    float32 array [R | t]."""
    values = np.frombuffer(data, dtype="<f4").astype(np.float32).reshape(-1, 12)
    return np.concatenate([values[:, :9].reshape(-1, 3, 3), values[:, 9:].reshape(-1, 3, 1)],
                          axis=2)


def event_from(response: pb.DeformResponse, decoder: codec.FrameDecoder,
               notices: List[pb.Notice]) -> Event:
    """A DeformResponse as the Frame or the Notice (also appended to `notices`) it carries;
    DeformError(INTERNAL) naming the problem for a frame that does not decode."""
    if response.HasField("notice"):
        notices.append(response.notice)
        return response.notice
    try:
        return _frame_from(response.frame, decoder)
    except ValueError as error:
        raise DeformError(grpc.StatusCode.INTERNAL, f"a frame did not decode: {error}") \
            from None


class PoseNumbering:
    """Turns send_pose's arguments into a DeformRequest and numbers the poses: one more than the
    largest sent so far unless given, the first 1. Callers serialize their calls."""

    def __init__(self) -> None:
        self._next_sequence = 1

    def request(self, pose: object, sequence: Optional[int],
                tools: Optional[ToolSpec]) -> Tuple[pb.DeformRequest, int]:
        states = tool_states(tools)
        update = pose_update(pose, int(self._next_sequence if sequence is None else sequence),
                             time.monotonic_ns())
        if states:
            del update.tools[:]
            update.tools.extend(states)
        self._next_sequence = max(self._next_sequence, update.sequence + 1)
        return pb.DeformRequest(pose=update), update.sequence


class DeformStream:
    def __init__(self, stub: object, start: pb.DeformStart, metadata: Sequence[Tuple[str, str]],
                 decoder: codec.FrameDecoder, timeout: Optional[float] = None,
                 reconnect: Optional[ReconnectPolicy] = None,
                 on_reconnect: Optional[OnReconnect] = None):
        """stub: a DeformServiceStub; start: the DeformStart message; metadata: call metadata;
        decoder: a codec.FrameDecoder for the mesh; timeout: the call's deadline in seconds
        (None: none; with reconnect, for all the calls together); reconnect: a ReconnectPolicy
        (None: the first loss ends the stream); on_reconnect: reconnect.OnReconnect."""
        self._stub = stub
        self._start = pb.DeformRequest(start=start)
        self._metadata = metadata
        self._decoder = decoder
        self._deadline = None if timeout is None else time.monotonic() + timeout
        self._policy = reconnect
        self._on_reconnect = on_reconnect
        self._jitter = random.Random()
        self._events: queue.Queue = queue.Queue()
        self._lock = threading.Lock()
        self._wake = threading.Event()  # set by close() and cancel(): ends a backoff's wait
        self._closing = False
        self._cancelled = False
        self._ended = False
        self._numbering = PoseNumbering()
        # Guarded by _lock: what a re-opened call sends again.
        self._latest_pose: Optional[pb.DeformRequest] = None
        self._latest_stiffness: Optional[pb.DeformRequest] = None
        self._attempts = 0        # re-opened calls since the last frame (reader thread only)
        self._lost_at = 0.0       # when the stream was lost, the first time since its last frame
        self.reconnects = 0       # calls re-opened after a loss (reconnect.py), in all
        self.notices: List[pb.Notice] = []  # every Notice taken so far (rejections, switches)
        self._requests: queue.Queue = queue.Queue()
        self._requests.put(self._start)
        self._call = self._open(self._requests, timeout)
        self._reader = threading.Thread(target=self._read, name="deform-stream-reader",
                                        daemon=True)
        self._reader.start()

    def _open(self, requests: queue.Queue, timeout: Optional[float]) -> Any:
        return self._stub.Deform(self._request_iterator(requests),  # type: ignore
                                 metadata=self._metadata, timeout=timeout)

    # Sending.

    def send_pose(self, pose: object, sequence: Optional[int] = None,
                  tools: Optional[ToolSpec] = None) -> int:
        """Sends a pose (poses.py: "knee:flexion:90", {"joint":..., "axis":..., "degrees":...},
        a list of them, or a PoseUpdate, whose own sequence is kept when set), with `tools`
        (tools.py: "sphere:X,Y,Z,R", a list of tools, or None: the PoseUpdate's own, if any; a
        pose without tools is the tool-free frame). Returns its sequence number (one more than the
        largest sent so far unless given; the first is 1). RuntimeError once the stream is closed
        or ended; ValueError for a malformed pose or tool."""
        with self._lock:
            self._check_open_locked()
            request, sequence = self._numbering.request(pose, sequence, tools)
            self._latest_pose = request
            self._requests.put(request)  # a lost call's queue is read no more: the next resends
            return sequence

    def send_stiffness(self, stiffness: pb.StiffnessUpdate) -> None:
        """Sends a StiffnessUpdate message (replaces the stream's stiffness)."""
        with self._lock:
            self._check_open_locked()
            self._latest_stiffness = pb.DeformRequest(stiffness=stiffness)
            self._requests.put(self._latest_stiffness)

    def _check_open_locked(self) -> None:
        if self._closing or self._cancelled or self._ended:
            raise RuntimeError("the stream is closed")

    @staticmethod
    def _request_iterator(requests: queue.Queue) -> Iterator[pb.DeformRequest]:
        while True:
            request = requests.get()
            if request is None:
                return
            yield request

    # Receiving.

    def _read(self) -> None:
        call, requests = self._call, self._requests
        while True:
            outcome: object = _END
            try:
                for response in call:
                    if response.HasField("frame"):
                        self._attempts = 0  # healthy again: the next loss starts a fresh budget
                    self._events.put(response)
            except grpc.RpcError as error:
                if not (self._cancelled and error.code() == grpc.StatusCode.CANCELLED):
                    outcome = DeformError.from_rpc_error(error)
            finally:
                requests.put(None)  # lets gRPC's request thread finish
            if isinstance(outcome, DeformError) and self._policy is not None and \
                    is_loss(outcome, self._cancelled):
                reopened = self._reconnect(self._policy, outcome)
                if isinstance(reopened, tuple):
                    call, requests = reopened
                    continue
                outcome = reopened
            self._events.put(outcome)
            return

    def _reconnect(self, policy: ReconnectPolicy, loss: DeformError) -> object:
        """Waits out the backoff and opens the next call: (call, its request queue), or what ends
        the stream instead (a DeformError, or _END once the caller cancelled)."""
        if self._attempts == 0:
            self._lost_at = time.monotonic()
        while True:
            if self._cancelled:
                return _END
            if self._closing:
                return loss
            if time.monotonic() - self._lost_at >= policy.give_up_after:
                return loss
            self._attempts += 1
            if self._wake.wait(policy.delay(self._attempts, loss.retry_delay, self._jitter)):
                continue  # closed or cancelled meanwhile
            timeout = None
            if self._deadline is not None:
                timeout = self._deadline - time.monotonic()
                if timeout <= 0:
                    return DeformError(grpc.StatusCode.DEADLINE_EXCEEDED,
                                       f"the stream's deadline passed while it was lost ({loss})")
            with self._lock:
                if self._cancelled or self._closing:
                    continue
                requests: queue.Queue = queue.Queue()
                for request in (self._start, self._latest_pose, self._latest_stiffness):
                    if request is not None:
                        requests.put(request)
                call = self._open(requests, timeout)
                self._call, self._requests = call, requests
            self.reconnects += 1
            if self._on_reconnect is not None:
                self._on_reconnect(loss, self._attempts)
            return call, requests

    def next_event(self, timeout: Optional[float] = None) -> Optional[Event]:
        """The next Frame or Notice, or None once the stream has ended well. Raises DeformError
        when it failed, TimeoutError after `timeout` seconds without an event."""
        if self._ended:
            return None
        try:
            event = self._events.get(timeout=timeout)
        except queue.Empty:
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

    def next_frame(self, timeout: Optional[float] = None) -> Optional[Frame]:
        """The next Frame (notices in between go to self.notices), or None once the stream has
        ended well. A rejected pose has no frame: watch self.notices or use events()."""
        while True:
            event = self.next_event(timeout)
            if event is None or isinstance(event, Frame):
                return event

    def __iter__(self) -> Iterator[Frame]:
        """Frames until the stream ends (after close(), or the server ends it)."""
        while True:
            frame = self.next_frame()
            if frame is None:
                return
            yield frame

    def events(self) -> Iterator[Event]:
        """Frames and Notices until the stream ends."""
        while True:
            event = self.next_event()
            if event is None:
                return
            yield event

    # Ending.

    def close(self, timeout: float = 30.0) -> None:
        """Half-closes (no more sends), then waits up to `timeout` s for the server to end the
        stream, dropping frames not taken yet. Raises DeformError if the stream failed,
        TimeoutError (after cancelling the call) if it did not end in time."""
        with self._lock:
            if not self._closing:
                self._closing = True
                self._requests.put(None)
        self._wake.set()
        deadline = time.monotonic() + timeout
        try:
            while self.next_event(timeout=max(0.0, deadline - time.monotonic())) is not None:
                pass
        except TimeoutError:
            self.cancel()
            raise

    def cancel(self) -> None:
        """Cancels the call now; the stream ends quietly."""
        with self._lock:
            self._cancelled = True
            call, requests = self._call, self._requests
        self._wake.set()
        call.cancel()
        requests.put(None)

    def __enter__(self) -> "DeformStream":
        return self

    def __exit__(self, exc_type: object, exc: object, traceback: object) -> "Literal[False]":
        if exc_type is None:
            self.close()
        else:
            self.cancel()
        return False
