"""The Python client against a secured deformd: bearer tokens (--token-file; without a valid
token UNAUTHENTICATED, with one the whole session works, tenants see only their own meshes) and
mutual TLS (scripts/make-test-certificates.sh; CA, client certificate and key, server name)."""

import hashlib
import os
import pathlib
import secrets
import subprocess
import sys
import tempfile
import unittest

from deform_client import DeformClient, DeformError
from deformd_process import REPOSITORY, DeformdProcess

EXAMPLE = pathlib.Path(__file__).resolve().parents[1] / "examples" / "bend_knee.py"


def token_line(token, tenant, role="tenant"):
    return f"{hashlib.sha256(token.encode()).hexdigest()}  {tenant}  {role}\n"


def one_frame(client, mesh_id, encoding="predicted"):
    with client.stream(mesh_id, encoding=encoding) as stream:
        stream.send_pose("knee:flexion:90")
        return stream.next_frame(timeout=60)


class TokenTest(unittest.TestCase):
    def test_tokens_authenticate_and_separate_tenants(self):
        ward, other = secrets.token_hex(32), secrets.token_hex(32)
        with tempfile.TemporaryDirectory() as directory:
            tokens = pathlib.Path(directory) / "tokens"
            tokens.write_text("# sha256 tenant role\n" + token_line(ward, "ward-3") +
                              token_line(other, "ward-4"))
            with DeformdProcess("--workers", "2", "--token-file", tokens) as server:
                for token in (None, "not-a-token"):
                    with self.subTest(token=token):
                        anonymous = DeformClient(server.target, token=token)
                        with self.assertRaises(DeformError) as raised:
                            anonymous.list_meshes()
                        self.assertEqual(raised.exception.code_name, "UNAUTHENTICATED")
                        with self.assertRaises(DeformError) as raised:
                            anonymous.load_phantom(500)
                        self.assertEqual(raised.exception.code_name, "UNAUTHENTICATED")
                        anonymous.close()

                client = DeformClient(server.target, token=ward)
                stages = []
                mesh = client.load_phantom(800, progress=lambda stage, ms: stages.append(stage))
                self.assertEqual(stages[-1], "READY")
                self.assertEqual([m.mesh_id for m in client.list_meshes()], [mesh.mesh_id])
                self.assertEqual(client.info(mesh.mesh_id, geometry=True).triangles.shape,
                                 (mesh.triangle_count, 3))
                self.assertEqual(one_frame(client, mesh.mesh_id).positions.shape,
                                 (mesh.vertex_count, 3))

                neighbour = DeformClient(server.target, token=other)
                self.assertEqual(neighbour.list_meshes(), [])
                for call in (lambda: neighbour.info(mesh.mesh_id),
                             lambda: neighbour.stream(mesh.mesh_id),
                             lambda: neighbour.unload(mesh.mesh_id)):
                    with self.assertRaises(DeformError) as raised:
                        call()
                    self.assertEqual(raised.exception.code_name, "NOT_FOUND")
                client.unload(mesh.mesh_id)
                client.close()
                neighbour.close()


class TlsTest(unittest.TestCase):
    def test_mutual_tls_with_a_token(self):
        token = secrets.token_hex(32)
        with tempfile.TemporaryDirectory() as directory:
            certs = pathlib.Path(directory) / "certs"
            subprocess.run([str(REPOSITORY / "scripts" / "make-test-certificates.sh"),
                            str(certs)], check=True, capture_output=True, timeout=120)
            tokens = pathlib.Path(directory) / "tokens"
            tokens.write_text(token_line(token, "ward-3"))
            with DeformdProcess("--workers", "2", "--tls-cert", certs / "server.pem",
                                "--tls-key", certs / "server.key", "--tls-client-ca",
                                certs / "ca.pem", "--token-file", tokens) as server:
                # The server's certificate names localhost and 127.0.0.1; server_name picks one.
                client = DeformClient(server.target, ca=certs / "ca.pem",
                                      cert=certs / "client.pem", key=certs / "client.key",
                                      server_name="localhost", token=token)
                mesh = client.load_phantom(600)
                self.assertEqual(one_frame(client, mesh.mesh_id, "quantized").positions.shape,
                                 (mesh.vertex_count, 3))
                client.unload(mesh.mesh_id)
                client.close()

                # The example takes the same settings from the environment.
                environment = dict(os.environ, DEFORM_TLS="1", DEFORM_TLS_CA=str(certs / "ca.pem"),
                                   DEFORM_TLS_CERT=str(certs / "client.pem"),
                                   DEFORM_TLS_KEY=str(certs / "client.key"),
                                   DEFORM_TLS_SERVER_NAME="localhost", DEFORM_TOKEN=token)
                done = subprocess.run(
                    [sys.executable, str(EXAMPLE), "--target", server.target, "--vertices", "500",
                     "--out", str(pathlib.Path(directory) / "bent.ply")],
                    env=environment, capture_output=True, text=True, timeout=120)
                self.assertEqual(done.returncode, 0, done.stderr)
                self.assertIn("wrote", done.stdout)

                # PEM contents work as well as paths.
                pem = DeformClient(server.target, ca=(certs / "ca.pem").read_bytes(),
                                   cert=(certs / "client.pem").read_bytes(),
                                   key=(certs / "client.key").read_bytes(), token=token)
                self.assertEqual(pem.list_meshes(), [])
                pem.close()

                refused = {
                    "no client certificate": DeformClient(server.target, ca=certs / "ca.pem",
                                                          token=token, unary_timeout=10),
                    "another CA's client": DeformClient(
                        server.target, ca=certs / "ca.pem", cert=certs / "other-client.pem",
                        key=certs / "other-client.key", token=token, unary_timeout=10),
                    "plaintext": DeformClient(server.target, token=token, unary_timeout=10),
                    "an untrusted server": DeformClient(
                        server.target, ca=certs / "other-ca.pem", cert=certs / "client.pem",
                        key=certs / "client.key", token=token, unary_timeout=10),
                }
                for case, other in refused.items():
                    with self.subTest(case=case), self.assertRaises(DeformError) as raised:
                        other.list_meshes()
                    self.assertEqual(raised.exception.code_name, "UNAVAILABLE", case)
                    other.close()
        with self.assertRaises(ValueError):
            DeformClient("127.0.0.1:1", cert="client.pem")


if __name__ == "__main__":
    unittest.main()
