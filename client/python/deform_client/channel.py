"""How both clients reach deformd: the channel's options and, for TLS, its credentials.

Plaintext unless `tls=True` or any of `ca` (the CA that signed the server's certificate; None: the
system's roots), `cert` and `key` (the client's certificate chain and key, both or neither, for
mutual TLS) is given; `server_name` is the name the server's certificate must carry when it
differs from the target's host. Each of ca, cert and key is a file path or the PEM contents as
bytes. ValueError for a certificate without its key or a key without its certificate.
"""

from __future__ import annotations

import pathlib
from typing import List, Optional, Tuple, Union

import grpc

Pem = Union[str, pathlib.Path, bytes, None]
DEFAULT_MAX_RECEIVE_MESSAGE_BYTES = 256 << 20


def _pem(value: Pem) -> Optional[bytes]:
    if value is None:
        return None
    if isinstance(value, bytes):
        return value
    return pathlib.Path(value).read_bytes()


def channel_settings(tls: bool, ca: Pem, cert: Pem, key: Pem, server_name: Optional[str],
                     max_receive_message_bytes: int
                     ) -> Tuple[Optional[grpc.ChannelCredentials], List[Tuple[str, object]]]:
    """(credentials, options): credentials None for a plaintext channel."""
    if (cert is None) != (key is None):
        raise ValueError("a client certificate needs its key and a key its certificate")
    # A lost server is tried again within 100 ms to 1 s (gRPC's defaults: 1 s growing to 120 s),
    # so that a reconnecting stream (reconnect.py) finds the next server soon; the C++ library's
    # channel does the same (client/lib/deform_client.cc, MakeDeformChannel).
    options: List[Tuple[str, object]] = [
        ("grpc.max_receive_message_length", max_receive_message_bytes),
        ("grpc.max_send_message_length", -1),
        ("grpc.min_reconnect_backoff_ms", 100),
        ("grpc.initial_reconnect_backoff_ms", 100),
        ("grpc.max_reconnect_backoff_ms", 1000)]
    if not (tls or ca is not None or cert is not None):
        return None, options
    credentials = grpc.ssl_channel_credentials(root_certificates=_pem(ca),
                                               private_key=_pem(key),
                                               certificate_chain=_pem(cert))
    if server_name:
        options.append(("grpc.ssl_target_name_override", server_name))
    return credentials, options
