// LoadMesh, GetMeshInfo, ListMeshes and UnloadMesh through the client library, with each class of
// bad input answered by its status while another client's stream goes on.
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "core/geometry/skeleton.h"
#include "core/io/mesh_io.h"
#include "core/io/phantom.h"
#include "core/io/skeleton_io.h"
#include "service/context/service_context.h"
#include "tests/service/support/service_fixture.h"
#include "tests/shared_data.h"

namespace deform::test_support {
namespace {

using ::testing::ElementsAre;
using ::testing::HasSubstr;
using ::testing::StartsWith;

// A phantom written as OBJ bytes with its skeleton as JSON: an upload that needs no shared data.
struct UploadFiles {
  std::string mesh_path;
  std::string skeleton_path;
  std::string mesh_bytes;
  std::string skeleton_bytes;
  int vertices = 0;
};

UploadFiles WritePhantomFiles(int vertices) {
  UploadFiles files;
  auto phantom = MakeKneePhantom(vertices);
  EXPECT_TRUE(phantom.ok());
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() /
      ("deform_service_test_" + std::to_string(::getpid()) + "_" + std::to_string(vertices));
  std::filesystem::create_directories(dir);
  files.mesh_path = (dir / "phantom.obj").string();
  files.skeleton_path = (dir / "phantom.json").string();
  EXPECT_TRUE(WriteMeshFile(phantom->mesh, files.mesh_path).ok());
  files.skeleton_bytes = SkeletonToJson(phantom->skeleton);
  std::ofstream(files.skeleton_path) << files.skeleton_bytes;
  std::ifstream in(files.mesh_path, std::ios::binary);
  std::ostringstream bytes;
  bytes << in.rdbuf();
  files.mesh_bytes = bytes.str();
  files.vertices = phantom->mesh.num_vertices();
  return files;
}

class LoadMeshTest : public ServiceTest {};

TEST_F(LoadMeshTest, PhantomLoadReportsEveryStageInOrder) {
  StartServer();
  std::vector<v1::LoadMeshResponse::Stage> stages;
  std::vector<double> elapsed;
  v1::MeshSummary summary;
  const grpc::Status status = client_->LoadPhantom(
      600, {}, &summary,
      [&](const v1::LoadMeshResponse& progress) {
        stages.push_back(progress.stage());
        elapsed.push_back(progress.elapsed_ms());
      },
      "knee");
  ASSERT_TRUE(status.ok()) << status.error_message();
  EXPECT_THAT(
      stages,
      ElementsAre(v1::LoadMeshResponse::STAGE_RECEIVED, v1::LoadMeshResponse::STAGE_VALIDATED,
                  v1::LoadMeshResponse::STAGE_WEIGHTS, v1::LoadMeshResponse::STAGE_FACTORISED,
                  v1::LoadMeshResponse::STAGE_READY));
  for (std::size_t k = 1; k < elapsed.size(); ++k) EXPECT_LE(elapsed[k - 1], elapsed[k]);

  auto phantom = MakeKneePhantom(600);
  ASSERT_TRUE(phantom.ok());
  EXPECT_EQ(summary.name(), "knee");
  EXPECT_EQ(summary.vertex_count(), static_cast<std::uint32_t>(phantom->mesh.num_vertices()));
  EXPECT_EQ(summary.triangle_count(), static_cast<std::uint32_t>(phantom->mesh.num_triangles()));
  EXPECT_EQ(summary.bone_count(), 2u);
  EXPECT_GT(summary.factor_bytes(), 0u);
  ASSERT_EQ(summary.joints_size(), 3);
  EXPECT_EQ(summary.joints(1).name(), "knee");
  EXPECT_TRUE(summary.joints(1).has_region());
  EXPECT_FALSE(summary.joints(0).has_region());
  ASSERT_GE(summary.joints(1).dofs_size(), 1);
  EXPECT_EQ(summary.joints(1).dofs(0).name(), "flexion");

  std::vector<v1::MeshSummary> meshes;
  ASSERT_TRUE(client_->ListMeshes(&meshes).ok());
  ASSERT_EQ(meshes.size(), 2u);  // the background mesh and this one
  EXPECT_EQ(meshes[0].mesh_id(), background_mesh_id_);
  EXPECT_EQ(meshes[0].open_streams(), 1u);
  EXPECT_EQ(meshes[1].mesh_id(), summary.mesh_id());

  v1::GetMeshInfoResponse info;
  ASSERT_TRUE(client_->GetMeshInfo(summary.mesh_id(), true, &info).ok());
  EXPECT_EQ(info.summary().mesh_id(), summary.mesh_id());
  const std::vector<float> rest = client::DecodePositions(info.rest_positions());
  ASSERT_EQ(rest.size(), 3u * phantom->mesh.num_vertices());
  for (int i = 0; i < phantom->mesh.num_vertices(); ++i) {
    for (int c = 0; c < 3; ++c) {
      EXPECT_FLOAT_EQ(rest[3 * i + c], static_cast<float>(phantom->mesh.vertices(i, c)));
    }
  }
  EXPECT_EQ(info.triangles().size(), 12u * phantom->mesh.num_triangles());
  v1::GetMeshInfoResponse without;
  ASSERT_TRUE(client_->GetMeshInfo(summary.mesh_id(), false, &without).ok());
  EXPECT_TRUE(without.rest_positions().empty());
  ExpectBackgroundStreamAlive();
}

TEST_F(LoadMeshTest, UploadedFilesBuildTheMesh) {
  StartServer();
  const UploadFiles files = WritePhantomFiles(800);
  v1::MeshSummary summary;
  std::vector<v1::LoadMeshResponse::Stage> stages;
  const grpc::Status status = client_->LoadMeshFiles(
      files.mesh_path, files.skeleton_path, {}, &summary,
      [&](const v1::LoadMeshResponse& progress) { stages.push_back(progress.stage()); });
  ASSERT_TRUE(status.ok()) << status.error_message();
  EXPECT_EQ(summary.vertex_count(), static_cast<std::uint32_t>(files.vertices));
  EXPECT_EQ(summary.name(), "phantom.obj");
  EXPECT_EQ(stages.back(), v1::LoadMeshResponse::STAGE_READY);
  EXPECT_EQ(stages.front(), v1::LoadMeshResponse::STAGE_RECEIVED);

  // Small chunks arrive the same.
  client::ClientOptions small_chunks;
  small_chunks.upload_chunk_bytes = 1000;
  client::DeformClient chunked(server_->target(), small_chunks);
  ASSERT_TRUE(chunked
                  .LoadMeshBytes("chunked", v1::MESH_FORMAT_OBJ, files.mesh_bytes,
                                 v1::SKELETON_FORMAT_JSON, files.skeleton_bytes, {}, &summary)
                  .ok());
  EXPECT_EQ(summary.vertex_count(), static_cast<std::uint32_t>(files.vertices));
}

TEST_F(LoadMeshTest, SharedLegUploads) {
  DEFORM_REQUIRE_SHARED_FILE(mesh, "leg/leg_1633.obj");
  DEFORM_REQUIRE_SHARED_FILE(skeleton, "leg/leg.tgf");
  StartServer();
  v1::MeshSummary summary;
  const grpc::Status status = client_->LoadMeshFiles(mesh, skeleton, {}, &summary);
  ASSERT_TRUE(status.ok()) << status.error_message();
  EXPECT_EQ(summary.vertex_count(), 1633u);
  EXPECT_EQ(summary.joints_size(), 5);
}

TEST_F(LoadMeshTest, MissingFileIsNotFoundWithoutContactingTheServer) {
  client::DeformClient offline("127.0.0.1:1");
  v1::MeshSummary summary;
  EXPECT_EQ(offline.LoadMeshFiles("/nonexistent/mesh.obj", "/nonexistent/leg.tgf", {}, &summary)
                .error_code(),
            grpc::StatusCode::NOT_FOUND);
}

TEST_F(LoadMeshTest, UnknownMeshIsNotFound) {
  StartServer();
  v1::GetMeshInfoResponse info;
  const grpc::Status info_status = client_->GetMeshInfo("mesh-999", false, &info);
  EXPECT_EQ(info_status.error_code(), grpc::StatusCode::NOT_FOUND);
  EXPECT_THAT(info_status.error_message(), HasSubstr("mesh-999"));
  EXPECT_EQ(client_->UnloadMesh("mesh-999").error_code(), grpc::StatusCode::NOT_FOUND);
  EXPECT_EQ(client_->UnloadMesh("").error_code(), grpc::StatusCode::NOT_FOUND);
  StreamRecorder recorder;
  auto stream = client_->OpenStream("mesh-999", recorder.Callbacks());
  EXPECT_EQ(stream->Wait().error_code(), grpc::StatusCode::NOT_FOUND);
  ExpectBackgroundStreamAlive();
}

TEST_F(LoadMeshTest, TruncatedUploadIsInvalidArgument) {
  StartServer();
  grpc::ClientContext context;
  auto stream = client_->stub()->LoadMesh(&context);
  v1::LoadMeshRequest request;
  v1::UploadSource* upload = request.mutable_header()->mutable_upload();
  upload->set_format(v1::MESH_FORMAT_OBJ);
  upload->set_mesh_size_bytes(1000);
  upload->set_skeleton_format(v1::SKELETON_FORMAT_TGF);
  upload->set_skeleton("1 0 0 0\n2 0 1 0\n#\n1 2\n#\n");
  ASSERT_TRUE(stream->Write(request));
  request.set_chunk(std::string(400, 'v'));
  stream->Write(request);
  stream->WritesDone();
  v1::LoadMeshResponse progress;
  while (stream->Read(&progress)) {
  }
  const grpc::Status status = stream->Finish();
  EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_THAT(status.error_message(), HasSubstr("truncated upload: received 400 of the 1000"));
  ExpectBackgroundStreamAlive();
}

TEST_F(LoadMeshTest, ProtocolViolationsAreInvalidArgument) {
  StartServer();
  {
    grpc::ClientContext context;
    auto stream = client_->stub()->LoadMesh(&context);
    v1::LoadMeshRequest request;
    request.set_chunk("v 0 0 0\n");
    stream->Write(request);
    stream->WritesDone();
    const grpc::Status status = stream->Finish();
    EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
    EXPECT_THAT(status.error_message(), HasSubstr("header"));
  }
  {
    grpc::ClientContext context;
    auto stream = client_->stub()->LoadMesh(&context);
    stream->WritesDone();
    EXPECT_EQ(stream->Finish().error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  }
  {
    v1::MeshSummary summary;
    const grpc::Status status = client_->LoadMeshBytes("x", v1::MESH_FORMAT_UNSPECIFIED, "v 0 0 0",
                                                       v1::SKELETON_FORMAT_TGF, "#", {}, &summary);
    EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
    EXPECT_THAT(status.error_message(), HasSubstr("format"));
  }
  ExpectBackgroundStreamAlive();
}

TEST_F(LoadMeshTest, GarbageMeshIsInvalidArgumentNamingTheMesh) {
  StartServer();
  const UploadFiles files = WritePhantomFiles(400);
  std::string garbage;
  for (int i = 0; i < 5000; ++i) garbage.push_back(static_cast<char>((i * 7919 + 13) % 251));
  v1::MeshSummary summary;
  for (const v1::MeshFormat format :
       {v1::MESH_FORMAT_OBJ, v1::MESH_FORMAT_PLY, v1::MESH_FORMAT_STL, v1::MESH_FORMAT_OFF}) {
    const grpc::Status status = client_->LoadMeshBytes(
        "garbage", format, garbage, v1::SKELETON_FORMAT_JSON, files.skeleton_bytes, {}, &summary);
    EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT) << format;
    EXPECT_THAT(status.error_message(), StartsWith("mesh")) << status.error_message();
  }
  // A file cut in half (with the size announced right): faces lost, vertices unused.
  const std::string half = files.mesh_bytes.substr(0, files.mesh_bytes.size() / 2);
  const grpc::Status cut =
      client_->LoadMeshBytes("half", v1::MESH_FORMAT_OBJ, half, v1::SKELETON_FORMAT_JSON,
                             files.skeleton_bytes, {}, &summary);
  EXPECT_EQ(cut.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_THAT(cut.error_message(), StartsWith("mesh")) << cut.error_message();
  ExpectBackgroundStreamAlive();
  std::vector<v1::MeshSummary> meshes;
  ASSERT_TRUE(client_->ListMeshes(&meshes).ok());
  EXPECT_EQ(meshes.size(), 1u);  // nothing half-registered
}

TEST_F(LoadMeshTest, BadSkeletonOrOptionsAreInvalidArgument) {
  StartServer();
  const UploadFiles files = WritePhantomFiles(400);
  v1::MeshSummary summary;
  const grpc::Status skeleton =
      client_->LoadMeshBytes("bad skeleton", v1::MESH_FORMAT_OBJ, files.mesh_bytes,
                             v1::SKELETON_FORMAT_JSON, "{ not json", {}, &summary);
  EXPECT_EQ(skeleton.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_THAT(skeleton.error_message(), StartsWith("skeleton"));

  v1::MethodOptions options;
  v1::JointRadius* radius = options.add_region_radii();
  radius->set_joint("elbow");
  radius->set_radius(1);
  const grpc::Status unknown_joint = client_->LoadPhantom(400, options, &summary);
  EXPECT_EQ(unknown_joint.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_THAT(unknown_joint.error_message(), HasSubstr("elbow"));

  v1::MethodOptions negative;
  negative.mutable_default_material()->set_soft(-1);
  EXPECT_EQ(client_->LoadPhantom(400, negative, &summary).error_code(),
            grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_EQ(client_->LoadPhantom(-5, {}, &summary).error_code(),
            grpc::StatusCode::INVALID_ARGUMENT);
  v1::MethodOptions unknown_blend;
  unknown_blend.set_rotation_blend(static_cast<v1::RotationBlend>(7));
  const grpc::Status blend = client_->LoadPhantom(400, unknown_blend, &summary);
  EXPECT_EQ(blend.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_THAT(blend.error_message(), HasSubstr("rotation_blend"));
  v1::MethodOptions absurd_segments;
  absurd_segments.set_rotation_blend(v1::ROTATION_BLEND_LINEAR);
  absurd_segments.set_linear_blend_segments(1u << 30);
  const grpc::Status segments = client_->LoadPhantom(400, absurd_segments, &summary);
  EXPECT_EQ(segments.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_THAT(segments.error_message(), HasSubstr("linear_blend_segments"));
  ExpectBackgroundStreamAlive();
}

TEST_F(LoadMeshTest, TooManyVerticesIsResourceExhausted) {
  service::ServerOptions options = TestServerOptions();
  options.limits.max_vertices = 1000;
  StartServer(options);
  v1::MeshSummary summary;
  const grpc::Status phantom = client_->LoadPhantom(2000, {}, &summary);
  EXPECT_EQ(phantom.error_code(), grpc::StatusCode::RESOURCE_EXHAUSTED);
  EXPECT_THAT(phantom.error_message(), HasSubstr("1000"));
  const UploadFiles files = WritePhantomFiles(2000);
  const grpc::Status upload =
      client_->LoadMeshFiles(files.mesh_path, files.skeleton_path, {}, &summary);
  EXPECT_EQ(upload.error_code(), grpc::StatusCode::RESOURCE_EXHAUSTED) << upload.error_message();
  ExpectBackgroundStreamAlive();
}

TEST_F(LoadMeshTest, TooManyMeshesIsResourceExhausted) {
  service::ServerOptions options = TestServerOptions();
  options.limits.max_meshes = 2;
  StartServer(options);
  const std::string second = LoadPhantom(301);  // the background mesh is the first
  v1::MeshSummary summary;
  const grpc::Status third = client_->LoadPhantom(302, {}, &summary);
  EXPECT_EQ(third.error_code(), grpc::StatusCode::RESOURCE_EXHAUSTED);
  EXPECT_THAT(third.error_message(), HasSubstr("mesh limit"));
  ExpectBackgroundStreamAlive();
  ASSERT_TRUE(client_->UnloadMesh(second).ok());
  EXPECT_TRUE(client_->LoadPhantom(302, {}, &summary).ok());
}

TEST_F(LoadMeshTest, MemoryBudgetIsResourceExhausted) {
  service::ServerOptions options = TestServerOptions();
  // The background phantom and its stream (with its constraints' scratch) fit; a 3000-vertex
  // phantom (about 7 MiB) does not.
  options.limits.max_memory_bytes = 2 << 20;
  StartServer(options);
  v1::MeshSummary summary;
  const grpc::Status status = client_->LoadPhantom(3000, {}, &summary);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::RESOURCE_EXHAUSTED);
  EXPECT_THAT(status.error_message(), HasSubstr("memory budget"));
  ExpectBackgroundStreamAlive();
}

TEST_F(LoadMeshTest, APhantomThatCannotFitIsRefusedBeforeAnythingIsBuilt) {
  // A request of a few bytes for a model far larger than the budget: refused at the header, before
  // the phantom is made (no stage reported), naming the estimate and the budget.
  service::ServerOptions options = TestServerOptions();
  options.limits.max_memory_bytes = std::size_t{256} << 20;
  StartServer(options);
  std::vector<v1::LoadMeshResponse::Stage> stages;
  v1::MeshSummary summary;
  const grpc::Status status = client_->LoadPhantom(
      200'000, {}, &summary,
      [&](const v1::LoadMeshResponse& progress) { stages.push_back(progress.stage()); });
  EXPECT_EQ(status.error_code(), grpc::StatusCode::RESOURCE_EXHAUSTED);
  EXPECT_THAT(status.error_message(), HasSubstr("a phantom of 200000 vertices needs about"));
  EXPECT_THAT(status.error_message(), HasSubstr("of the 256 MiB budget"));
  EXPECT_TRUE(stages.empty()) << stages.size() << " stages were reported before the refusal";
  EXPECT_EQ(server_->server().context().admission().loads_in_progress(), 0);
  EXPECT_EQ(server_->server().context().admission().memory_bytes_reserved(), 0u);
  ExpectBackgroundStreamAlive();
}

TEST_F(LoadMeshTest, AFileDeclaringAMeshThatCannotFitIsRefusedBeforeItIsParsed) {
  // A few hundred bytes whose header declares a mesh far larger than the budget (or the vertex
  // limit): refused from the declared counts, naming them, before the parser allocates anything;
  // never a parse error about the missing data.
  service::ServerOptions options = TestServerOptions();
  options.limits.max_memory_bytes = std::size_t{256} << 20;
  StartServer(options);
  const UploadFiles files = WritePhantomFiles(300);
  v1::MeshSummary summary;
  const std::string off = "OFF\n1000000 2000000 0\n0 0 0\n1 0 0\n0 1 0\n";
  const grpc::Status budget =
      client_->LoadMeshBytes("declared", v1::MESH_FORMAT_OFF, off, v1::SKELETON_FORMAT_JSON,
                             files.skeleton_bytes, {}, &summary);
  EXPECT_EQ(budget.error_code(), grpc::StatusCode::RESOURCE_EXHAUSTED) << budget.error_message();
  EXPECT_THAT(budget.error_message(),
              HasSubstr("a mesh of 1000000 vertices and 2000000 faces (as its off data declares)"));
  EXPECT_THAT(budget.error_message(), HasSubstr("of the 256 MiB budget"));
  const std::string ply =
      "ply\nformat ascii 1.0\nelement vertex 3000000\nproperty float x\nproperty float y\n"
      "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n";
  const grpc::Status limit =
      client_->LoadMeshBytes("declared", v1::MESH_FORMAT_PLY, ply, v1::SKELETON_FORMAT_JSON,
                             files.skeleton_bytes, {}, &summary);
  EXPECT_EQ(limit.error_code(), grpc::StatusCode::RESOURCE_EXHAUSTED) << limit.error_message();
  EXPECT_THAT(limit.error_message(), HasSubstr("declares 3000000 vertices"));
  EXPECT_THAT(limit.error_message(), HasSubstr("--max-vertices"));
  EXPECT_EQ(server_->server().context().admission().loads_in_progress(), 0);
  EXPECT_EQ(server_->server().context().admission().memory_bytes_reserved(), 0u);
  // A file that declares what it holds loads as before.
  EXPECT_TRUE(client_
                  ->LoadMeshBytes("fits", v1::MESH_FORMAT_OBJ, files.mesh_bytes,
                                  v1::SKELETON_FORMAT_JSON, files.skeleton_bytes, {}, &summary)
                  .ok());
  ExpectBackgroundStreamAlive();
}

TEST_F(LoadMeshTest, AnUploadInFlightHoldsItsBytesOfTheBudgetUntilItEnds) {
  service::ServerOptions options = TestServerOptions();
  options.limits.max_memory_bytes = std::size_t{64} << 20;
  StartServer(options);
  service::Admission& admission = server_->server().context().admission();
  // An upload that announces 56 MiB and sends nothing more.
  auto context = std::make_unique<grpc::ClientContext>();
  auto stream = client_->stub()->LoadMesh(context.get());
  v1::LoadMeshRequest request;
  v1::UploadSource* upload = request.mutable_header()->mutable_upload();
  upload->set_format(v1::MESH_FORMAT_OBJ);
  upload->set_mesh_size_bytes(std::uint64_t{56} << 20);
  upload->set_skeleton_format(v1::SKELETON_FORMAT_TGF);
  upload->set_skeleton("1 0 0 0\n2 0 1 0\n#\n1 2\n#\n");
  ASSERT_TRUE(stream->Write(request));
  for (int i = 0; i < 600 && admission.memory_bytes_reserved() == 0; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  ASSERT_GE(admission.memory_bytes_reserved(), std::size_t{56} << 20);

  // A phantom that would fit in the budget alone does not fit beside the upload's bytes.
  v1::MeshSummary summary;
  const grpc::Status refused = client_->LoadPhantom(12'000, {}, &summary);
  EXPECT_EQ(refused.error_code(), grpc::StatusCode::RESOURCE_EXHAUSTED);
  EXPECT_THAT(refused.error_message(), HasSubstr("a phantom of 12000 vertices needs about"));

  // The upload ends (its client cancels): its bytes and its slot are released.
  context->TryCancel();
  (void)stream->Finish();
  for (int i = 0; i < 600 && admission.loads_in_progress() != 0; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  EXPECT_EQ(admission.loads_in_progress(), 0);
  EXPECT_EQ(admission.memory_bytes_reserved(), 0u);
  EXPECT_TRUE(client_->LoadPhantom(12'000, {}, &summary).ok());
  ExpectBackgroundStreamAlive();
}

// Starts a LoadMesh of a large phantom on `stream` and reads its progress until the build has
// begun (STAGE_VALIDATED: admitted, the phantom made, the model's precomputation under way).
void StartLargePhantomBuild(
    grpc::ClientReaderWriter<v1::LoadMeshRequest, v1::LoadMeshResponse>* stream) {
  v1::LoadMeshRequest request;
  request.mutable_header()->mutable_phantom()->set_vertices(100'000);
  ASSERT_TRUE(stream->Write(request));
  ASSERT_TRUE(stream->WritesDone());
  v1::LoadMeshResponse progress;
  while (stream->Read(&progress)) {
    if (progress.stage() == v1::LoadMeshResponse::STAGE_VALIDATED) return;
  }
  FAIL() << "the load ended before its build began";
}

TEST_F(LoadMeshTest, AClientsCancelStopsItsBuildAndFreesTheSlot) {
  StartServer();
  const service::Admission& admission = server_->server().context().admission();
  const service::MeshRegistry& registry = server_->server().context().registry();
  const int registered_before = registry.registrations();
  grpc::ClientContext context;
  auto stream = client_->stub()->LoadMesh(&context);
  StartLargePhantomBuild(stream.get());
  context.TryCancel();
  EXPECT_EQ(stream->Finish().error_code(), grpc::StatusCode::CANCELLED);
  for (int i = 0; i < 1200 && admission.loads_in_progress() != 0; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  EXPECT_EQ(admission.loads_in_progress(), 0);
  EXPECT_EQ(admission.memory_bytes_reserved(), 0u);
  // The build stopped between two phases: its model was never made, let alone registered.
  EXPECT_EQ(registry.registrations(), registered_before);
  ExpectBackgroundStreamAlive();
}

TEST_F(LoadMeshTest, ShutdownStopsABuildInProgress) {
  StartServer();
  const service::Admission& admission = server_->server().context().admission();
  const service::MeshRegistry& registry = server_->server().context().registry();
  const int registered_before = registry.registrations();
  grpc::ClientContext context;
  auto stream = client_->stub()->LoadMesh(&context);
  StartLargePhantomBuild(stream.get());
  expect_background_ok_at_end_ = false;  // drained by the shutdown
  server_->server().Shutdown(std::chrono::milliseconds(100));
  // Shutdown returns once the workers have stopped: the build ended without a model.
  EXPECT_EQ(admission.loads_in_progress(), 0);
  EXPECT_EQ(registry.registrations(), registered_before);
  const grpc::Status status = stream->Finish();
  EXPECT_TRUE(status.error_code() == grpc::StatusCode::UNAVAILABLE ||
              status.error_code() == grpc::StatusCode::CANCELLED)
      << status.error_code() << " " << status.error_message();
}

// An upload's header announcing 1000 mesh bytes, and its first 100.
void StartUpload(grpc::ClientReaderWriter<v1::LoadMeshRequest, v1::LoadMeshResponse>* stream) {
  v1::LoadMeshRequest request;
  v1::UploadSource* upload = request.mutable_header()->mutable_upload();
  upload->set_format(v1::MESH_FORMAT_OBJ);
  upload->set_mesh_size_bytes(1000);
  upload->set_skeleton_format(v1::SKELETON_FORMAT_TGF);
  upload->set_skeleton("1 0 0 0\n2 0 1 0\n#\n1 2\n#\n");
  ASSERT_TRUE(stream->Write(request));
  request.set_chunk(std::string(100, ' '));
  ASSERT_TRUE(stream->Write(request));
}

TEST_F(LoadMeshTest, AStalledUploadEndsAfterTheIdleTimeoutAndFreesItsSlot) {
  service::ServerOptions options = TestServerOptions();
  options.limits.upload_idle_timeout_ms = 300;
  options.limits.max_meshes = 2;  // the background mesh and the upload
  StartServer(options);
  grpc::ClientContext context;
  context.set_deadline(std::chrono::system_clock::now() + std::chrono::seconds(120));
  auto stream = client_->stub()->LoadMesh(&context);
  StartUpload(stream.get());
  v1::LoadMeshResponse progress;
  while (stream->Read(&progress)) {
  }
  const grpc::Status status = stream->Finish();
  EXPECT_EQ(status.error_code(), grpc::StatusCode::DEADLINE_EXCEEDED);
  EXPECT_THAT(status.error_message(),
              HasSubstr("no upload data for 0.3 s (--upload-idle-timeout-s)"));
  const service::Admission& admission = server_->server().context().admission();
  for (int i = 0; i < 1200 && admission.loads_in_progress() != 0; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  EXPECT_EQ(admission.loads_in_progress(), 0);
  v1::MeshSummary summary;
  EXPECT_TRUE(client_->LoadPhantom(300, {}, &summary).ok());  // the slot is free again
  ExpectBackgroundStreamAlive();
}

TEST_F(LoadMeshTest, AnUploadThatNeverEndsStopsAtTheTimeLimit) {
  service::ServerOptions options = TestServerOptions();
  options.limits.upload_idle_timeout_ms = 0;
  options.limits.upload_time_limit_ms = 500;
  StartServer(options);
  grpc::ClientContext context;
  context.set_deadline(std::chrono::system_clock::now() + std::chrono::seconds(120));
  auto stream = client_->stub()->LoadMesh(&context);
  StartUpload(stream.get());
  // A byte now and then: never idle, never complete.
  v1::LoadMeshRequest trickle;
  trickle.set_chunk(" ");
  while (stream->Write(trickle)) std::this_thread::sleep_for(std::chrono::milliseconds(50));
  v1::LoadMeshResponse progress;
  while (stream->Read(&progress)) {
  }
  const grpc::Status status = stream->Finish();
  EXPECT_EQ(status.error_code(), grpc::StatusCode::DEADLINE_EXCEEDED);
  EXPECT_THAT(status.error_message(),
              HasSubstr("the upload took longer than 0.5 s (--upload-time-limit-s)"));
  ExpectBackgroundStreamAlive();
}

TEST_F(LoadMeshTest, UploadLimitIsResourceExhausted) {
  service::ServerOptions options = TestServerOptions();
  options.limits.max_upload_bytes = 4096;
  StartServer(options);
  const UploadFiles files = WritePhantomFiles(400);
  v1::MeshSummary summary;
  const grpc::Status status =
      client_->LoadMeshBytes("big", v1::MESH_FORMAT_OBJ, files.mesh_bytes, v1::SKELETON_FORMAT_JSON,
                             files.skeleton_bytes, {}, &summary);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::RESOURCE_EXHAUSTED);
  EXPECT_THAT(status.error_message(), HasSubstr("exceeds the limit of 4096 bytes"));
  ExpectBackgroundStreamAlive();
}

}  // namespace
}  // namespace deform::test_support
