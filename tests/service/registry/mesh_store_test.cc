// --store: meshes come back after a restart under their ids and owners, built from what was
// uploaded; unloading deletes them; the files are private; a corrupt entry is skipped.
#include "service/registry/mesh_store.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <sys/types.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "core/io/mesh_io.h"
#include "core/io/phantom.h"
#include "core/io/skeleton_io.h"
#include "service/access/identity.h"
#include "service/registry/mesh_id.h"
#include "tests/service/support/stream_recorder.h"
#include "tests/service/support/temp_dir.h"
#include "tests/service/support/test_server.h"

namespace deform {
namespace {

using test_support::StreamRecorder;
using test_support::TempDir;
using test_support::TestServer;
using test_support::TestServerOptions;

client::ClientOptions WithToken(const std::string& token) {
  client::ClientOptions options;
  options.token = token;
  return options;
}

std::vector<std::string> EntryFiles(const std::string& dir) {
  std::vector<std::string> names;
  for (const auto& file : std::filesystem::directory_iterator(dir)) {
    const std::string name = file.path().filename().string();
    if (name != service::MeshStore::kLockFileName) names.push_back(name);
  }
  std::sort(names.begin(), names.end());
  return names;
}

int Mode(const std::string& path) {
  struct stat info {};
  EXPECT_EQ(::stat(path.c_str(), &info), 0) << path;
  return static_cast<int>(info.st_mode & 0777);
}

class MeshStoreTest : public ::testing::Test {
 protected:
  MeshStoreTest() {
    tokens_ = dir_.Write("tokens", service::Sha256Hex("token-a") + " ward-a tenant\n" +
                                       service::Sha256Hex("token-b") + " ward-b tenant\n");
    store_ = dir_.Path("store");
  }

  TempDir dir_;
  std::string tokens_;
  std::string store_;
};

// A server started on the store with tokens, as deformd --store --token-file does.
class StoredServer {
 public:
  StoredServer(const std::string& store, const std::string& tokens,
               const std::string& key_file = "") {
    server_ = std::make_unique<service::DeformServer>(TestServerOptions());
    EXPECT_TRUE(server_->UseTokenFile(tokens).ok());
    const Status used = server_->UseStore(store, &restored_, key_file);
    EXPECT_TRUE(used.ok()) << used.ToString();
    EXPECT_TRUE(server_->Start().ok());
  }
  std::unique_ptr<client::DeformClient> NewClient(const std::string& token) const {
    return std::make_unique<client::DeformClient>("127.0.0.1:" + std::to_string(server_->port()),
                                                  WithToken(token));
  }
  int restored() const { return restored_; }

 private:
  std::unique_ptr<service::DeformServer> server_;
  int restored_ = 0;
};

std::string UploadPhantomAsObj(client::DeformClient& client, const TempDir& dir) {
  auto phantom = MakeKneePhantom(400);
  EXPECT_TRUE(phantom.ok());
  const std::string mesh_path = dir.Path("phantom.obj");
  EXPECT_TRUE(WriteMeshFile(phantom->mesh, mesh_path).ok());
  const std::string skeleton_path = dir.Write("phantom.json", SkeletonToJson(phantom->skeleton));
  v1::MethodOptions options;
  options.set_rotation_blend(v1::ROTATION_BLEND_LINEAR);
  v1::MeshSummary summary;
  const grpc::Status status = client.LoadMeshFiles(mesh_path, skeleton_path, options, &summary);
  EXPECT_TRUE(status.ok()) << status.error_message();
  return summary.mesh_id();
}

TEST_F(MeshStoreTest, MeshesComeBackWithTheirIdsAndOwnersAndUnloadDeletesThem) {
  std::string upload_id, phantom_id;
  v1::GetMeshInfoResponse before;
  {
    StoredServer server(store_, tokens_);
    EXPECT_EQ(server.restored(), 0);
    auto ward_a = server.NewClient("token-a");
    auto ward_b = server.NewClient("token-b");
    upload_id = UploadPhantomAsObj(*ward_a, dir_);
    ASSERT_TRUE(ward_a->GetMeshInfo(upload_id, true, &before).ok());
    v1::MeshSummary summary;
    ASSERT_TRUE(ward_b->LoadPhantom(300, {}, &summary, {}, "bed 7").ok());
    phantom_id = summary.mesh_id();
  }
  EXPECT_EQ(Mode(store_), 0700);
  EXPECT_EQ(EntryFiles(store_),
            (std::vector<std::string>{std::min(upload_id, phantom_id) + ".mesh",
                                      std::max(upload_id, phantom_id) + ".mesh"}));
  for (const std::string& name : EntryFiles(store_)) EXPECT_EQ(Mode(store_ + "/" + name), 0600);

  StoredServer restarted(store_, tokens_);
  EXPECT_EQ(restarted.restored(), 2);
  auto ward_a = restarted.NewClient("token-a");
  auto ward_b = restarted.NewClient("token-b");
  std::vector<v1::MeshSummary> meshes;
  ASSERT_TRUE(ward_a->ListMeshes(&meshes).ok());
  ASSERT_EQ(meshes.size(), 1u);  // the owner is kept: ward A sees only its upload
  EXPECT_EQ(meshes[0].mesh_id(), upload_id);
  v1::GetMeshInfoResponse after;
  ASSERT_TRUE(ward_a->GetMeshInfo(upload_id, true, &after).ok());
  EXPECT_EQ(after.summary().name(), before.summary().name());
  EXPECT_EQ(after.summary().vertex_count(), before.summary().vertex_count());
  EXPECT_EQ(after.rest_positions(), before.rest_positions());
  EXPECT_EQ(after.triangles(), before.triangles());
  EXPECT_EQ(after.summary().rotation_blend(), v1::ROTATION_BLEND_LINEAR);  // options kept
  EXPECT_EQ(ward_a->GetMeshInfo(phantom_id, false, &after).error_code(),
            grpc::StatusCode::NOT_FOUND);
  ASSERT_TRUE(ward_b->GetMeshInfo(phantom_id, false, &after).ok());
  EXPECT_EQ(after.summary().name(), "bed 7");

  // The restored mesh serves frames under its old id.
  StreamRecorder recorder;
  auto stream = ward_a->OpenStream(upload_id, recorder.Callbacks());
  v1::PoseUpdate pose;
  pose.set_sequence(1);
  ASSERT_TRUE(stream->SendPose(pose));
  EXPECT_TRUE(recorder.WaitForFrames(1));
  stream->Close();
  EXPECT_TRUE(stream->Wait().ok());

  ASSERT_TRUE(ward_a->UnloadMesh(upload_id).ok());
  EXPECT_EQ(EntryFiles(store_), std::vector<std::string>{phantom_id + ".mesh"});
}

TEST_F(MeshStoreTest, BoneSurfacesAndConstraintOptionsComeBack) {
  auto phantom = MakeKneePhantom(600);
  ASSERT_TRUE(phantom.ok());
  const std::string mesh_path = dir_.Path("leg.obj");
  ASSERT_TRUE(WriteMeshFile(phantom->mesh, mesh_path).ok());
  const std::string skeleton_path = dir_.Write("leg.json", SkeletonToJson(phantom->skeleton));
  const std::string femur_path = dir_.Path("femur.obj");
  ASSERT_TRUE(WriteMeshFile(phantom->bones[0].mesh, femur_path).ok());
  v1::MethodOptions options;
  options.mutable_constraints()->set_contacts(false);
  options.mutable_constraints()->set_contact_margin(0.002);
  std::string upload_id, phantom_id;
  v1::GetMeshInfoResponse before;
  {
    StoredServer server(store_, tokens_);
    auto ward_a = server.NewClient("token-a");
    v1::MeshSummary summary;
    const grpc::Status status = ward_a->LoadMeshFiles(mesh_path, skeleton_path, options, &summary,
                                                      {}, "", {femur_path + ":hip"});
    ASSERT_TRUE(status.ok()) << status.error_message();
    upload_id = summary.mesh_id();
    ASSERT_TRUE(ward_a->GetMeshInfo(upload_id, true, &before).ok());
    v1::LoadMeshHeader header;
    header.mutable_phantom()->set_vertices(300);
    header.mutable_phantom()->set_without_bones(true);
    ASSERT_TRUE(ward_a->LoadMesh(header, {}, &summary).ok());
    phantom_id = summary.mesh_id();
  }
  ASSERT_EQ(before.summary().bone_surfaces_size(), 1);

  StoredServer restarted(store_, tokens_);
  EXPECT_EQ(restarted.restored(), 2);
  auto ward_a = restarted.NewClient("token-a");
  v1::GetMeshInfoResponse after;
  ASSERT_TRUE(ward_a->GetMeshInfo(upload_id, true, &after).ok());
  ASSERT_EQ(after.summary().bone_surfaces_size(), 1);
  EXPECT_EQ(after.summary().bone_surfaces(0).name(), "femur");
  EXPECT_EQ(after.summary().bone_surfaces(0).bone(), 0u);
  EXPECT_EQ(after.summary().bone_surfaces(0).triangle_count(),
            before.summary().bone_surfaces(0).triangle_count());
  ASSERT_EQ(after.bone_surfaces_size(), 1);
  EXPECT_EQ(after.bone_surfaces(0).rest_positions(), before.bone_surfaces(0).rest_positions());
  EXPECT_EQ(after.bone_surfaces(0).triangles(), before.bone_surfaces(0).triangles());
  EXPECT_FALSE(after.summary().constraints().contacts());
  EXPECT_TRUE(after.summary().constraints().keep_volume());
  EXPECT_DOUBLE_EQ(after.summary().constraints().contact_margin(), 0.002);
  ASSERT_TRUE(ward_a->GetMeshInfo(phantom_id, false, &after).ok());
  EXPECT_EQ(after.summary().bone_surfaces_size(), 0);  // without_bones kept
}

TEST_F(MeshStoreTest, ACorruptEntryIsSkippedAndTheRestRestored) {
  std::string good_id;
  {
    StoredServer server(store_, tokens_);
    v1::MeshSummary summary;
    ASSERT_TRUE(server.NewClient("token-a")->LoadPhantom(300, {}, &summary).ok());
    good_id = summary.mesh_id();
  }
  // A truncated copy of the good entry, a garbage entry and an altered byte.
  std::ifstream in(store_ + "/" + good_id + ".mesh", std::ios::binary);
  const std::string good((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const std::string truncated_id = service::NewMeshId();
  std::ofstream(store_ + "/" + truncated_id + ".mesh", std::ios::binary)
      << good.substr(0, good.size() / 2);
  std::ofstream(store_ + "/" + service::NewMeshId() + ".mesh") << "garbage";
  std::string altered = good;
  altered[altered.size() / 2] ^= 0x20;
  std::ofstream(store_ + "/" + service::NewMeshId() + ".mesh", std::ios::binary) << altered;
  std::ofstream(store_ + "/." + service::NewMeshId() + ".pending") << "an unfinished load";

  StoredServer restarted(store_, tokens_);
  EXPECT_EQ(restarted.restored(), 1);
  std::vector<v1::MeshSummary> meshes;
  ASSERT_TRUE(restarted.NewClient("token-a")->ListMeshes(&meshes).ok());
  ASSERT_EQ(meshes.size(), 1u);
  EXPECT_EQ(meshes[0].mesh_id(), good_id);
  for (const std::string& name : EntryFiles(store_)) EXPECT_NE(name[0], '.') << name;
}

TEST_F(MeshStoreTest, AFailedLoadLeavesNothingInTheStore) {
  StoredServer server(store_, tokens_);
  auto ward_a = server.NewClient("token-a");
  v1::LoadMeshHeader header;
  header.mutable_upload()->set_format(v1::MESH_FORMAT_OBJ);
  header.mutable_upload()->set_skeleton_format(v1::SKELETON_FORMAT_TGF);
  header.mutable_upload()->set_skeleton("1 0 0 0\n2 0 1 0\n#\n1 2\n");
  v1::MeshSummary summary;
  EXPECT_EQ(ward_a->LoadMesh(header, "v 0 0 0\nf 1 2 3\n", &summary).error_code(),
            grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_TRUE(EntryFiles(store_).empty());
}

// A FIFO or a directory named like an entry never blocks the start: logged and skipped (a FIFO
// used to stop the server before it listened).
TEST_F(MeshStoreTest, AFifoOrADirectoryNamedLikeAnEntryIsSkippedWithoutBlocking) {
  std::string good_id;
  {
    StoredServer server(store_, tokens_);
    v1::MeshSummary summary;
    ASSERT_TRUE(server.NewClient("token-a")->LoadPhantom(300, {}, &summary).ok());
    good_id = summary.mesh_id();
  }
  ASSERT_EQ(::mkfifo((store_ + "/" + service::NewMeshId() + ".mesh").c_str(), 0600), 0);
  std::filesystem::create_directory(store_ + "/" + service::NewMeshId() + ".mesh");
  const auto start = std::chrono::steady_clock::now();
  StoredServer restarted(store_, tokens_);
  EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::seconds(10));
  EXPECT_EQ(restarted.restored(), 1);
}

// Two servers on one store destroyed each other's entries: the second is refused while the first
// holds the store's lock, and may open it once the first is gone.
TEST_F(MeshStoreTest, ASecondServerOnTheSameStoreIsRefused) {
  auto first = service::MeshStore::Open(store_);
  ASSERT_TRUE(first.ok()) << first.status().ToString();
  auto second = service::MeshStore::Open(store_);
  ASSERT_FALSE(second.ok());
  EXPECT_EQ(second.status().code(), StatusCode::kFailedPrecondition);
  EXPECT_THAT(second.status().message(), ::testing::HasSubstr("another deformd uses this store"));
  // Another process too (flock is per open file, so a child's own open is refused the same way).
  const pid_t child = ::fork();
  if (child == 0) _exit(service::MeshStore::Open(store_).ok() ? 0 : 3);
  int status = 0;
  ASSERT_EQ(::waitpid(child, &status, 0), child);
  EXPECT_EQ(WEXITSTATUS(status), 3);
  first->reset();
  EXPECT_TRUE(service::MeshStore::Open(store_).ok());
}

// An UnloadMesh whose entry cannot be deleted answered OK and the mesh came back after a restart:
// now it is INTERNAL and the mesh stays loaded.
TEST_F(MeshStoreTest, AnUnloadWhoseEntryCannotBeDeletedFailsAndKeepsTheMesh) {
  StoredServer server(store_, tokens_);
  auto client = server.NewClient("token-a");
  v1::MeshSummary summary;
  ASSERT_TRUE(client->LoadPhantom(300, {}, &summary).ok());
  const std::string entry = store_ + "/" + summary.mesh_id() + ".mesh";
  // The entry replaced by a non-empty directory: unlink fails (EISDIR), whoever runs the test.
  std::filesystem::remove(entry);
  std::filesystem::create_directory(entry);
  std::ofstream(entry + "/keep") << "x";
  const grpc::Status unloaded = client->UnloadMesh(summary.mesh_id());
  EXPECT_EQ(unloaded.error_code(), grpc::StatusCode::INTERNAL);
  EXPECT_THAT(unloaded.error_message(), ::testing::HasSubstr("stays loaded"));
  std::vector<v1::MeshSummary> meshes;
  ASSERT_TRUE(client->ListMeshes(&meshes).ok());
  ASSERT_EQ(meshes.size(), 1u);
  EXPECT_EQ(meshes[0].mesh_id(), summary.mesh_id());
}

// An entry whose tenant was edited and whose checksum was recomputed was restored as the other
// tenant's: with --store-key the entries carry an HMAC under a key outside the store, and such an
// entry is refused at restore.
TEST_F(MeshStoreTest, AnEntryWhoseOwnerWasEditedIsRefusedWithAKey) {
  const std::string key = dir_.Path("store.key");  // beside the token file, outside the store
  std::string id;
  {
    StoredServer server(store_, tokens_, key);
    v1::MeshSummary summary;
    ASSERT_TRUE(server.NewClient("token-a")->LoadPhantom(300, {}, &summary).ok());
    id = summary.mesh_id();
  }
  EXPECT_EQ(Mode(key), 0600);
  {
    StoredServer server(store_, tokens_, key);  // untouched: restored
    EXPECT_EQ(server.restored(), 1);
  }
  const std::string path = store_ + "/" + id + ".mesh";
  std::ifstream in(path, std::ios::binary);
  std::string entry((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  in.close();
  const std::size_t at = entry.find("ward-a");
  ASSERT_NE(at, std::string::npos);
  entry.replace(at, 6, "ward-b");
  // The seal recomputed as a SHA-256, all an editor without the key can do.
  std::string body = entry.substr(0, entry.size() - 32);
  const std::string hex = service::Sha256Hex(body);
  std::string digest;
  for (std::size_t i = 0; i < hex.size(); i += 2) {
    digest.push_back(static_cast<char>(std::stoi(hex.substr(i, 2), nullptr, 16)));
  }
  std::ofstream(path, std::ios::binary | std::ios::trunc) << body + digest;
  StoredServer restarted(store_, tokens_, key);
  EXPECT_EQ(restarted.restored(), 0);
  std::vector<v1::MeshSummary> meshes;
  ASSERT_TRUE(restarted.NewClient("token-b")->ListMeshes(&meshes).ok());
  EXPECT_TRUE(meshes.empty()) << "ward-b was handed ward-a's mesh";
  // A key inside the store is refused.
  auto inside = service::MeshStore::Open(dir_.Path("other-store"), dir_.Path("other-store/key"));
  EXPECT_FALSE(inside.ok());
}

}  // namespace
}  // namespace deform
