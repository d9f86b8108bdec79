// The real deformd and command-line clients in processes: SIGHUP rotates tokens; plaintext on a
// non-loopback address needs --plaintext; the health probe and deform-vr talk TLS with a token;
// --store brings a mesh back after a restart under its id (the same pose, the same frame).
#include "tests/service/support/deformd_process.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cstdlib>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "deform_client.h"
#include "service/access/identity.h"
#include "tests/service/support/temp_dir.h"
#include "tests/service/support/test_certificates.h"

namespace deform {
namespace {

using test_support::DeformdProcess;
using test_support::TempDir;
using test_support::TestCertificates;
using ::testing::HasSubstr;

std::string TokenLine(const std::string& token, const std::string& tenant) {
  return service::Sha256Hex(token) + " " + tenant + " tenant\n";
}

std::string ReadFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

// Runs a command line with its stdout discarded and its stderr kept: a failing expectation on the
// exit status shows what the command said.
struct CommandResult {
  int status;
  std::string stderr_text;
};
CommandResult RunCommand(const std::string& command, const std::string& stderr_path) {
  const int status = std::system((command + " >/dev/null 2>" + stderr_path).c_str());
  return {status, ReadFile(stderr_path)};
}

grpc::Status List(const std::string& target, const std::string& token) {
  client::ClientOptions options;
  options.token = token;
  options.unary_deadline_ms = 10'000;
  client::DeformClient client(target, options);
  std::vector<v1::MeshSummary> meshes;
  return client.ListMeshes(&meshes);
}

TEST(DeformdProcessTest, SighupReloadsTheTokenFile) {
  TempDir dir;
  const std::string tokens = dir.Write("tokens", TokenLine("first-token", "ward-a"));
  DeformdProcess deformd({"--listen", "127.0.0.1:0", "--workers", "1", "--token-file", tokens},
                         dir.Path("log"));
  ASSERT_TRUE(deformd.WaitForListening()) << deformd.Log();
  EXPECT_TRUE(List(deformd.target(), "first-token").ok());
  EXPECT_EQ(List(deformd.target(), "second-token").error_code(), grpc::StatusCode::UNAUTHENTICATED);

  dir.Write("tokens", TokenLine("second-token", "ward-a"));
  deformd.Signal(SIGHUP);
  ASSERT_TRUE(deformd.WaitForLog("token file reloaded")) << deformd.Log();
  EXPECT_TRUE(List(deformd.target(), "second-token").ok());
  EXPECT_EQ(List(deformd.target(), "first-token").error_code(), grpc::StatusCode::UNAUTHENTICATED);

  dir.Write("tokens", "garbage\n");
  deformd.Signal(SIGHUP);
  ASSERT_TRUE(deformd.WaitForLog("reload failed")) << deformd.Log();
  EXPECT_TRUE(List(deformd.target(), "second-token").ok());
  EXPECT_EQ(deformd.Stop(), 0);
  EXPECT_THAT(deformd.Log(), HasSubstr("[audit] tenant=ward-a action=list"));
}

TEST(DeformdProcessTest, PlaintextOnAllInterfacesOnlyWithThePlaintextFlag) {
  TempDir dir;
  DeformdProcess refused({"--listen", "0.0.0.0:0", "--workers", "1"}, dir.Path("refused.log"));
  EXPECT_EQ(refused.WaitForExit(), 1);
  EXPECT_THAT(refused.Log(), HasSubstr("--plaintext"));

  DeformdProcess allowed({"--listen", "0.0.0.0:0", "--workers", "1", "--plaintext"},
                         dir.Path("allowed.log"));
  EXPECT_TRUE(allowed.WaitForLog("(plaintext)")) << allowed.Log();
  EXPECT_EQ(allowed.Stop(), 0);
}

TEST(DeformdProcessTest, CommandLineClientsTalkTlsWithAToken) {
  TestCertificates certificates;
  ASSERT_TRUE(certificates.ok());
  TempDir dir;
  const std::string tokens = dir.Write("tokens", TokenLine("vr-token", "ward-a"));
  DeformdProcess deformd(
      {"--listen", "127.0.0.1:0", "--workers", "1", "--token-file", tokens, "--tls-cert",
       certificates.Path("server.pem"), "--tls-key", certificates.Path("server.key"),
       "--tls-client-ca", certificates.Path("ca.pem")},
      dir.Path("log"));
  ASSERT_TRUE(deformd.WaitForListening()) << deformd.Log();
  EXPECT_THAT(deformd.Log(), HasSubstr("(mutual TLS)"));
  const std::string tls = " --tls-ca " + certificates.Path("ca.pem") + " --tls-cert " +
                          certificates.Path("client.pem") + " --tls-key " +
                          certificates.Path("client.key") + " --tls-server-name localhost";
  const std::string probe = std::string(DEFORM_PROBE_PATH) + " --target " + deformd.target();
  const CommandResult probed = RunCommand(probe + tls, dir.Path("probe.err"));
  EXPECT_EQ(probed.status, 0) << probed.stderr_text << deformd.Log();
  // Plaintext to a TLS port: no connection is made (exit 2, as grpc_health_probe's).
  const CommandResult plain =
      RunCommand(probe + " --connect-timeout-ms 1000", dir.Path("plain.err"));
  EXPECT_TRUE(WIFEXITED(plain.status) && WEXITSTATUS(plain.status) == 2) << plain.stderr_text;

  const std::string vr = std::string(DEFORM_VR_PATH) + " --target " + deformd.target() +
                         " --phantom-vertices 300 --pose knee:flexion:30 --frames 1 --out " +
                         dir.Path("bent.obj");
  const CommandResult bent = RunCommand("DEFORM_TOKEN=vr-token " + vr + tls, dir.Path("bent.err"));
  EXPECT_EQ(bent.status, 0) << bent.stderr_text << deformd.Log();
  EXPECT_TRUE(std::ifstream(dir.Path("bent.obj")).good());
  const CommandResult without_token = RunCommand(vr + tls, dir.Path("vr.err"));
  EXPECT_NE(without_token.status, 0);
  EXPECT_THAT(without_token.stderr_text.substr(0, without_token.stderr_text.find('\n')),
              HasSubstr("UNAUTHENTICATED"));
  EXPECT_EQ(deformd.Stop(), 0);
}

TEST(DeformdProcessTest, StoreBringsAMeshBackAfterARestart) {
  TempDir dir;
  const std::vector<std::string> args = {"--listen", "127.0.0.1:0", "--workers",
                                         "1",        "--store",     dir.Path("store")};
  std::string mesh_id;
  {
    DeformdProcess deformd(args, dir.Path("first.log"));
    ASSERT_TRUE(deformd.WaitForListening()) << deformd.Log();
    const std::string vr = std::string(DEFORM_VR_PATH) + " --target " + deformd.target() +
                           " --phantom-vertices 300 --pose knee:flexion:60 --frames 1 --keep-mesh" +
                           " --out " + dir.Path("before.obj");
    const CommandResult before = RunCommand(vr, dir.Path("before.err"));
    ASSERT_EQ(before.status, 0) << before.stderr_text << deformd.Log();
    client::DeformClient client(deformd.target());
    std::vector<v1::MeshSummary> meshes;
    ASSERT_TRUE(client.ListMeshes(&meshes).ok());
    ASSERT_EQ(meshes.size(), 1u);
    mesh_id = meshes[0].mesh_id();
    EXPECT_EQ(deformd.Stop(), 0);
  }
  DeformdProcess restarted(args, dir.Path("second.log"));
  ASSERT_TRUE(restarted.WaitForListening()) << restarted.Log();
  EXPECT_THAT(restarted.Log(), HasSubstr("store: mesh=" + mesh_id + " tenant=default restored"));
  const std::string vr = std::string(DEFORM_VR_PATH) + " --target " + restarted.target() +
                         " --mesh-id " + mesh_id + " --pose knee:flexion:60 --frames 1 --out " +
                         dir.Path("after.obj");
  const CommandResult after = RunCommand(vr, dir.Path("after.err"));
  ASSERT_EQ(after.status, 0) << after.stderr_text << restarted.Log();
  EXPECT_EQ(ReadFile(dir.Path("after.obj")), ReadFile(dir.Path("before.obj")));
  client::DeformClient client(restarted.target());
  ASSERT_TRUE(client.UnloadMesh(mesh_id).ok());
  EXPECT_FALSE(std::ifstream(dir.Path("store") + "/" + mesh_id + ".mesh").good());
  EXPECT_EQ(restarted.Stop(), 0);
}

}  // namespace
}  // namespace deform
