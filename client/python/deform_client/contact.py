"""Contact queries (docs/instruments.md): a tool's contact with the skin at haptic rate, one
blocking round trip a query over a QueryContact stream.

    with client.contact(mesh_id, deform_stream_id=frame.message.stream_id) as contact:
        result = contact.query("sphere:0,6,0.86,0.3")
        print(result.depth, result.force)

A result is the ContactResult message (point, normal, depth, force, signed_distance,
material_weight, frame_number, frame_sequence). Errors raise DeformError; after one the stream has
ended.
"""

from __future__ import annotations

import queue
from typing import Any, Iterator, Optional, Sequence, Tuple

import grpc

from .errors import DeformError
from .stubs import pb
from .tools import tool_state


class ContactQuery:
    def __init__(self, stub: Any, start: Any, metadata: Sequence[Tuple[str, str]]) -> None:
        self._requests: "queue.Queue[Any]" = queue.Queue()
        self._requests.put(pb.QueryContactRequest(start=start))
        self._responses: Iterator[Any] = stub.QueryContact(iter(self._requests.get, None), metadata=metadata)
        self._sequence = 0
        self._closed = False
        response = self._next()
        if not response.HasField("started"):
            self.close()
            raise DeformError(grpc.StatusCode.INTERNAL,
                              "QueryContact: the server's first answer is not `started`")
        self.started = response.started  # bounding_box_diagonal, stiffness

    def _next(self) -> Any:
        try:
            return next(self._responses)
        except grpc.RpcError as error:
            self._closed = True
            raise DeformError.from_rpc_error(error) from None
        except StopIteration:
            self._closed = True
            raise DeformError(grpc.StatusCode.UNAVAILABLE, "QueryContact: stream ended") from None

    def query(self, tool: Any) -> Any:
        """The ContactResult of `tool` (any form tool_state accepts) against the skin as it
        stands: the named Deform stream's latest frame, or the rest pose."""
        self._sequence += 1
        request = pb.ContactQuery(sequence=self._sequence, tool=tool_state(tool))
        self._requests.put(pb.QueryContactRequest(query=request))
        response = self._next()
        if not response.HasField("result") or response.result.sequence != self._sequence:
            raise DeformError(grpc.StatusCode.INTERNAL,
                              f"QueryContact: no result for query {self._sequence}")
        return response.result

    def close(self) -> None:
        """Half-closes and waits for the server's end; raises its error, if any."""
        if self._closed:
            return
        self._closed = True
        self._requests.put(None)
        try:
            for _ in self._responses:
                pass
        except grpc.RpcError as error:
            raise DeformError.from_rpc_error(error) from None

    def __enter__(self) -> "ContactQuery":
        return self

    def __exit__(self, *exc: Optional[object]) -> None:
        self.close()
