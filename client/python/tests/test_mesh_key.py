"""The calls that name a mesh carry it as routing metadata, and info() rides out a replica that
is still building the mesh: both clients against a small in-process DeformService (no deformd),
which records each call's metadata and answers as a replica of a cluster does (docs/cluster.md).

GetMeshInfo, UnloadMesh, Deform and QueryContact send "deform-mesh-key: <mesh id>" beside the
token; ListMeshes and LoadMesh name no mesh and send none, nor does a call naming an id that is
not printable ASCII of at most 128 bytes. A GetMeshInfo answered UNAVAILABLE with a RetryInfo is
asked again after the delay the details give, within the call's timeout; without a RetryInfo, or
when the delay would pass the timeout, the UNAVAILABLE reaches the caller."""

import asyncio
import concurrent.futures
import threading
import unittest

import grpc

from deform_client import (MESH_KEY_HEADER, AsyncDeformClient, DeformClient, DeformError,
                           pb)
from deform_client._proto import rpc_error_details_pb2, rpc_status_pb2
from deform_client.errors import STATUS_DETAILS_KEY
from deform_client.stubs import grpc_stubs

TOKEN = "mesh-key-test-token"


def status_details(retry_ms):
    """A serialized google.rpc.Status with a RetryInfo of `retry_ms`, as the server sends it."""
    retry = rpc_error_details_pb2.RetryInfo()
    retry.retry_delay.FromMilliseconds(retry_ms)
    status = rpc_status_pb2.Status(code=grpc.StatusCode.UNAVAILABLE.value[0], message="building")
    detail = status.details.add()
    detail.type_url = "type.googleapis.com/google.rpc.RetryInfo"
    detail.value = retry.SerializeToString()
    return status.SerializeToString()


class RecordingService(grpc_stubs.DeformServiceServicer):
    """Keeps (method, metadata dict) per call. GetMeshInfo answers UNAVAILABLE `unavailable`
    times first, with a RetryInfo of `retry_ms` unless it is 0."""

    def __init__(self):
        self.lock = threading.Lock()
        self.calls = []
        self.unavailable = 0
        self.retry_ms = 0

    def record(self, method, context):
        with self.lock:
            self.calls.append((method, dict(context.invocation_metadata())))

    def keys(self, method):
        with self.lock:
            return [metadata.get(MESH_KEY_HEADER) for name, metadata in self.calls
                    if name == method]

    def GetMeshInfo(self, request, context):
        self.record("GetMeshInfo", context)
        with self.lock:
            refuse = self.unavailable > 0
            self.unavailable -= 1
        if refuse:
            if self.retry_ms:
                details = status_details(self.retry_ms)
                context.set_trailing_metadata(((STATUS_DETAILS_KEY, details),))
            context.abort(grpc.StatusCode.UNAVAILABLE, "the mesh is being built here")
        return pb.GetMeshInfoResponse(summary=pb.MeshSummary(mesh_id=request.mesh_id,
                                                             vertex_count=3))

    def UnloadMesh(self, request, context):
        self.record("UnloadMesh", context)
        return pb.UnloadMeshResponse()

    def ListMeshes(self, request, context):
        self.record("ListMeshes", context)
        return pb.ListMeshesResponse()

    def Deform(self, request_iterator, context):
        self.record("Deform", context)
        for _ in request_iterator:
            pass
        return iter(())

    def QueryContact(self, request_iterator, context):
        self.record("QueryContact", context)
        yield pb.QueryContactResponse(started=pb.ContactQueryStarted())
        for _ in request_iterator:
            pass


class MeshKeyTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.service = RecordingService()
        cls.server = grpc.server(concurrent.futures.ThreadPoolExecutor(max_workers=4))
        grpc_stubs.add_DeformServiceServicer_to_server(cls.service, cls.server)
        cls.port = cls.server.add_insecure_port("127.0.0.1:0")
        cls.server.start()
        cls.target = f"127.0.0.1:{cls.port}"

    @classmethod
    def tearDownClass(cls):
        cls.server.stop(None)

    def setUp(self):
        with self.service.lock:
            self.service.calls.clear()
            self.service.unavailable = 0
            self.service.retry_ms = 0

    def test_calls_naming_a_mesh_carry_its_key_and_the_token(self):
        with DeformClient(self.target, token=TOKEN) as client:
            client.info("mesh-a")
            client.unload("mesh-b")
            client.list_meshes()
            with client.stream("mesh-c") as stream:
                stream.send_pose("knee:flexion:10")
            client.contact("mesh-d").close()
        self.assertEqual(self.service.keys("GetMeshInfo"), ["mesh-a", "mesh-c"])
        self.assertEqual(self.service.keys("UnloadMesh"), ["mesh-b"])
        self.assertEqual(self.service.keys("Deform"), ["mesh-c"])
        self.assertEqual(self.service.keys("QueryContact"), ["mesh-d"])
        self.assertEqual(self.service.keys("ListMeshes"), [None])
        for _, metadata in self.service.calls:
            self.assertEqual(metadata.get("authorization"), f"Bearer {TOKEN}")

    def test_an_id_no_server_has_is_sent_without_a_key(self):
        with DeformClient(self.target) as client:
            for mesh_id in ("two words", "é", "x" * 129, ""):
                client.info(mesh_id)
            client.info("x" * 128)
        self.assertEqual(self.service.keys("GetMeshInfo"), [None, None, None, None, "x" * 128])

    def test_the_async_client_carries_the_key_too(self):
        async def calls():
            async with AsyncDeformClient(self.target, token=TOKEN) as client:
                await client.info("mesh-a")
                await client.unload("mesh-b")
                async with await client.stream("mesh-c") as stream:
                    await stream.send_pose("knee:flexion:10")
        asyncio.run(calls())
        self.assertEqual(self.service.keys("GetMeshInfo"), ["mesh-a", "mesh-c"])
        self.assertEqual(self.service.keys("UnloadMesh"), ["mesh-b"])
        self.assertEqual(self.service.keys("Deform"), ["mesh-c"])

    def test_info_asks_again_after_a_retry_info(self):
        self.service.unavailable, self.service.retry_ms = 2, 50
        with DeformClient(self.target) as client:
            self.assertEqual(client.info("mesh-a").summary.mesh_id, "mesh-a")
        self.assertEqual(self.service.keys("GetMeshInfo"), ["mesh-a"] * 3)

    def test_async_info_asks_again_after_a_retry_info(self):
        self.service.unavailable, self.service.retry_ms = 2, 50

        async def info():
            async with AsyncDeformClient(self.target) as client:
                return await client.info("mesh-a")
        self.assertEqual(asyncio.run(info()).summary.mesh_id, "mesh-a")
        self.assertEqual(self.service.keys("GetMeshInfo"), ["mesh-a"] * 3)

    def test_unavailable_without_retry_info_reaches_the_caller(self):
        self.service.unavailable = 1
        with DeformClient(self.target) as client, self.assertRaises(DeformError) as raised:
            client.info("mesh-a")
        self.assertEqual(raised.exception.code, grpc.StatusCode.UNAVAILABLE)
        self.assertEqual(raised.exception.retry_delay, 0.0)
        self.assertEqual(len(self.service.keys("GetMeshInfo")), 1)

    def test_a_retry_past_the_timeout_is_not_waited_for(self):
        self.service.unavailable, self.service.retry_ms = 5, 2000
        with DeformClient(self.target) as client, self.assertRaises(DeformError) as raised:
            client.info("mesh-a", timeout=1.0)
        self.assertEqual(raised.exception.code, grpc.StatusCode.UNAVAILABLE)
        self.assertAlmostEqual(raised.exception.retry_delay, 2.0)
        self.assertEqual(len(self.service.keys("GetMeshInfo")), 1)  # asked once, not again


if __name__ == "__main__":
    unittest.main()
