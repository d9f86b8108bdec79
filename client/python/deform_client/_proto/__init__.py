"""The generated stubs, made by ../../generate_stubs.py; do not edit them, regenerate them:
deform.v1's (deform_pb2, deform_pb2_grpc) from proto/deform/v1/deform.proto, and google.rpc's
Status and error details under this package's own names (rpc_status_pb2,
rpc_error_details_pb2) from Debian's copy of the google/rpc protos."""
