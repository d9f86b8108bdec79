"""The protobuf and gRPC stubs of deform.v1, shipped in the package (deform_client/_proto/).

Exports `pb` (deform_pb2: the messages and enums) and `grpc_stubs` (deform_pb2_grpc:
DeformServiceStub). ../generate_stubs.py makes them from proto/deform/v1/deform.proto, and ctest's
python_client_stubs_current fails when they differ from what the proto generates.
"""

from ._proto import deform_pb2 as pb
from ._proto import deform_pb2_grpc as grpc_stubs

__all__ = ["grpc_stubs", "pb"]
