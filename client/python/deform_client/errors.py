"""DeformError: every failure of a deformd call, with its gRPC status code's name.

`code` is a grpc.StatusCode (NOT_FOUND, INVALID_ARGUMENT, UNAUTHENTICATED, ...), `code_name` its
name as a string, `details` the server's message. str(error) reads "NOT_FOUND: <message>".
`retry_delay` is the seconds the server asked the client to wait before calling again (a
google.rpc.RetryInfo in the status details: an UNAVAILABLE from a replica still building a mesh,
docs/cluster.md), 0.0 when it asked nothing.
"""

from __future__ import annotations

from typing import Any, Iterable, Optional, Union

import grpc
from google.protobuf.message import DecodeError

from ._proto import rpc_error_details_pb2, rpc_status_pb2

STATUS_DETAILS_KEY = "grpc-status-details-bin"
_RETRY_INFO_TYPE = "google.rpc.RetryInfo"
_MAX_RETRY_DELAY = 60.0  # a server's hint is bounded as the C++ library bounds it


class DeformError(Exception):
    def __init__(self, code: Union[grpc.StatusCode, str], details: str,
                 retry_delay: float = 0.0):
        self.code = code
        self.code_name = code.name if isinstance(code, grpc.StatusCode) else str(code)
        self.details = details
        self.retry_delay = retry_delay
        super().__init__(f"{self.code_name}: {details}")

    @classmethod
    def from_rpc_error(cls, error: grpc.RpcError) -> "DeformError":
        """A grpc.RpcError (a failed call) -> DeformError."""
        code = error.code() if hasattr(error, "code") else grpc.StatusCode.UNKNOWN
        details = error.details() if hasattr(error, "details") else str(error)
        trailing = error.trailing_metadata() if hasattr(error, "trailing_metadata") else None
        return cls(code, details or "", retry_delay_in(trailing))


def retry_delay_in(trailing_metadata: Optional[Iterable[Any]]) -> float:
    """The RetryInfo delay (seconds) of a call's status details, carried in its trailing metadata
    as a serialized google.rpc.Status; 0.0 without one (or with details that do not parse)."""
    for key, value in trailing_metadata or ():
        if key != STATUS_DETAILS_KEY or not isinstance(value, bytes):
            continue
        try:
            status = rpc_status_pb2.Status.FromString(value)
            for detail in status.details:
                if detail.type_url.rsplit("/", 1)[-1] != _RETRY_INFO_TYPE:
                    continue
                delay = rpc_error_details_pb2.RetryInfo.FromString(detail.value).retry_delay
                seconds = delay.seconds + delay.nanos / 1e9
                return min(max(seconds, 0.0), _MAX_RETRY_DELAY)
        except DecodeError:  # details this client cannot read: no hint
            return 0.0
    return 0.0
