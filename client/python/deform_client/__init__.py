"""deformd's Python client: load meshes, stream poses, receive frames as numpy arrays.

    from deform_client import DeformClient
    client = DeformClient("127.0.0.1:50051")
    mesh = client.load_phantom(2000, progress=lambda stage, ms: print(stage, ms))
    with client.stream(mesh.mesh_id, encoding="predicted") as stream:
        stream.send_pose("knee:flexion:90"); print(stream.next_frame().positions.shape)

Modules: client (DeformClient), async_client (AsyncDeformClient, AsyncDeformStream: the same on
asyncio), summary (MeshSummary, MeshInfo, Joint, Bone, BoneSurface...), stream (DeformStream,
Frame), contact (ContactQuery: a tool's contact at haptic rate), calls (what both clients send; timeouts: DEFAULT), channel (TLS), codec (the frame
decoders), meshopt (meshoptimizer's decoder through ctypes), poses (pose forms), tools (tool
forms), errors (DeformError), reconnect (ReconnectPolicy: streams that survive their server's
loss), stubs (the generated deform.v1 code shipped in _proto/, `pb`),
version (`__version__`, deformd's).
"""

from .async_client import AsyncDeformClient, AsyncDeformStream, async_client_from_environment
from .calls import DEFAULT, DEFAULT_LOAD_TIMEOUT, DEFAULT_UNARY_TIMEOUT, MESH_KEY_HEADER
from .client import DeformClient, client_from_environment
from .contact import ContactQuery
from .errors import DeformError
from .reconnect import ReconnectPolicy
from .stream import DeformStream, Frame
from .stubs import pb
from .summary import (Bone, BoneSurface, BoneSurfaceInfo, DegreeOfFreedom, Joint, MeshInfo,
                      MeshSummary)
from .tools import tool_state
from .version import __version__

__all__ = ["__version__", "AsyncDeformClient", "AsyncDeformStream", "Bone", "BoneSurface",
           "BoneSurfaceInfo", "ContactQuery", "DEFAULT", "DEFAULT_LOAD_TIMEOUT", "DEFAULT_UNARY_TIMEOUT",
           "DegreeOfFreedom", "DeformClient", "DeformError", "DeformStream", "Frame", "Joint",
           "MESH_KEY_HEADER", "MeshInfo", "MeshSummary", "ReconnectPolicy",
           "async_client_from_environment", "client_from_environment", "pb", "tool_state"]
