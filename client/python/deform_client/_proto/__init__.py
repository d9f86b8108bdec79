"""The generated deform.v1 stubs (deform_pb2, deform_pb2_grpc), made by ../../generate_stubs.py
from proto/deform/v1/deform.proto; do not edit them, regenerate them."""
