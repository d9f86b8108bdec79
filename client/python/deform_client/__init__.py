"""deformd's Python client: load meshes, stream poses, receive frames as numpy arrays.

    from deform_client import DeformClient
    client = DeformClient("127.0.0.1:50051")
    mesh = client.load_phantom(2000, progress=lambda stage, ms: print(stage, ms))
    with client.stream(mesh.mesh_id, encoding="predicted") as stream:
        stream.send_pose("knee:flexion:90"); print(stream.next_frame().positions.shape)

Modules: client (DeformClient, MeshInfo, BoneSurface), stream (DeformStream, Frame), contact
(ContactQuery), codec (the frame
decoders), meshopt (meshoptimizer's decoder through ctypes), poses (pose forms), tools (tool forms), errors
(DeformError), stubs (the generated deform.v1 code, `pb`: see stubs.py for where it is found).
"""

from .contact import ContactQuery
from .client import BoneSurface, DeformClient, MeshInfo, client_from_environment
from .errors import DeformError
from .stream import DeformStream, Frame
from .stubs import pb
from .tools import tool_state

__all__ = ["BoneSurface", "ContactQuery", "DeformClient", "DeformError", "DeformStream", "Frame", "MeshInfo",
           "client_from_environment", "pb", "tool_state"]
