// Mesh ids: a loaded mesh's id is its content key (mesh_key.h): the same content again is the same
// mesh, without a rebuild; two servers without a shared secret name it differently, and an id kept
// from a previous server is NOT_FOUND on the next one (instead of naming its first mesh). The ids
// of meshes loaded otherwise (--preload) are 128 random bits.
#include "service/registry/mesh_id.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <regex>
#include <set>
#include <string>
#include <vector>

#include "tests/service/support/stream_recorder.h"
#include "tests/service/support/test_server.h"

namespace deform {
namespace {

using test_support::StreamRecorder;
using test_support::TestServer;
using ::testing::HasSubstr;

std::string LoadPhantom(client::DeformClient& client) {
  v1::MeshSummary summary;
  const grpc::Status status = client.LoadPhantom(300, {}, &summary);
  EXPECT_TRUE(status.ok()) << status.error_message();
  return summary.mesh_id();
}

TEST(MeshIdTest, NewIdsAre128RandomBitsInHex) {
  const std::regex form("mesh-[0-9a-f]{32}");
  std::set<std::string> ids;
  std::set<char> digits_seen;
  for (int i = 0; i < 64; ++i) {
    const std::string id = service::NewMeshId();
    EXPECT_TRUE(std::regex_match(id, form)) << id;
    EXPECT_TRUE(service::LooksLikeMeshId(id)) << id;
    ids.insert(id);
    digits_seen.insert(id.begin() + 5, id.end());
  }
  EXPECT_EQ(ids.size(), 64u);
  EXPECT_EQ(digits_seen.size(), 16u);  // 64 x 32 random hex digits use every digit
  // About half of the 128 bits differ between two ids (a counter would differ in a few).
  int differing_bits = 0;
  const std::string a = *ids.begin(), b = *ids.rbegin();
  for (std::size_t i = 5; i < a.size(); ++i) {
    const int x = std::stoi(a.substr(i, 1), nullptr, 16) ^ std::stoi(b.substr(i, 1), nullptr, 16);
    differing_bits += __builtin_popcount(static_cast<unsigned>(x));
  }
  EXPECT_GT(differing_bits, 30);
  EXPECT_FALSE(service::LooksLikeMeshId("mesh-1"));
  EXPECT_FALSE(service::LooksLikeMeshId("mesh-0123456789ABCDEF0123456789abcdef"));
}

TEST(MeshIdTest, TheSameContentIsTheSameMeshWithoutARebuild) {
  TestServer server;
  auto client = server.NewClient();
  ASSERT_TRUE(client->WaitForReady(60'000));
  const std::string first = LoadPhantom(*client);
  const int registrations = server.server().context().registry().registrations();
  EXPECT_EQ(LoadPhantom(*client), first);
  EXPECT_EQ(server.server().context().registry().registrations(), registrations);
  EXPECT_EQ(server.server().context().registry().mesh_count(), 1);
  // Other content (another size) is another mesh.
  v1::MeshSummary other;
  ASSERT_TRUE(client->LoadPhantom(301, {}, &other).ok());
  EXPECT_NE(other.mesh_id(), first);
}

TEST(MeshIdTest, TwoServersWithoutASharedKeyNameTheSameContentDifferently) {
  std::vector<std::string> ids;
  for (int server_index = 0; server_index < 2; ++server_index) {
    TestServer server;
    auto client = server.NewClient();
    ASSERT_TRUE(client->WaitForReady(60'000));
    ids.push_back(LoadPhantom(*client));
  }
  const std::regex form("mesh-[0-9a-f]{32}");
  for (const std::string& id : ids) EXPECT_TRUE(std::regex_match(id, form)) << id;
  EXPECT_NE(ids[0], ids[1]);
}

TEST(MeshIdTest, StaleIdFromAPreviousServerIsNotFound) {
  std::string stale_id;
  {
    TestServer previous;
    auto client = previous.NewClient();
    ASSERT_TRUE(client->WaitForReady(60'000));
    stale_id = LoadPhantom(*client);
  }
  TestServer next;
  auto client = next.NewClient();
  ASSERT_TRUE(client->WaitForReady(60'000));
  const std::string fresh_id = LoadPhantom(*client);  // the new server's first mesh
  ASSERT_NE(fresh_id, stale_id);

  v1::GetMeshInfoResponse info;
  const grpc::Status info_status = client->GetMeshInfo(stale_id, false, &info);
  EXPECT_EQ(info_status.error_code(), grpc::StatusCode::NOT_FOUND);
  EXPECT_THAT(info_status.error_message(), HasSubstr(stale_id));
  StreamRecorder recorder;
  auto stream = client->OpenStream(stale_id, recorder.Callbacks());
  EXPECT_EQ(stream->Wait().error_code(), grpc::StatusCode::NOT_FOUND);
  EXPECT_EQ(client->UnloadMesh(stale_id).error_code(), grpc::StatusCode::NOT_FOUND);
  EXPECT_TRUE(client->GetMeshInfo(fresh_id, false, &info).ok());
}

}  // namespace
}  // namespace deform
