"""DeformError: every failure of a deformd call, with its gRPC status code's name.

`code` is a grpc.StatusCode (NOT_FOUND, INVALID_ARGUMENT, UNAUTHENTICATED, ...), `code_name` its
name as a string, `details` the server's message. str(error) reads "NOT_FOUND: <message>".
"""

from __future__ import annotations

from typing import Union

import grpc


class DeformError(Exception):
    def __init__(self, code: Union[grpc.StatusCode, str], details: str):
        self.code = code
        self.code_name = code.name if isinstance(code, grpc.StatusCode) else str(code)
        self.details = details
        super().__init__(f"{self.code_name}: {details}")

    @classmethod
    def from_rpc_error(cls, error: grpc.RpcError) -> "DeformError":
        """A grpc.RpcError (a failed call) -> DeformError."""
        code = error.code() if hasattr(error, "code") else grpc.StatusCode.UNKNOWN
        details = error.details() if hasattr(error, "details") else str(error)
        return cls(code, details or "")
