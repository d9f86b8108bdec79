// Bone surfaces through LoadMesh and GetMeshInfo: the phantom's three, an upload's files (named by
// bone index or joint), and each way a bone surface is refused while another client's stream goes
// on.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cstdint>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "core/io/mesh_io.h"
#include "core/io/phantom.h"
#include "core/io/skeleton_io.h"
#include "tests/service/support/service_fixture.h"
#include "tests/service/support/temp_dir.h"

namespace deform::test_support {
namespace {

using ::testing::HasSubstr;

// The phantom as upload files: its skin as OBJ, its skeleton as JSON, and each of its bone
// surfaces as NAME.obj (optionally scaled about its centroid).
struct PhantomFiles {
  std::string mesh;
  std::string skeleton;
  std::vector<std::string> bones;  // femur, tibia, patella
};

PhantomFiles WritePhantom(const TempDir& dir, int vertices, double bone_scale = 1) {
  PhantomFiles files;
  auto phantom = MakeKneePhantom(vertices);
  EXPECT_TRUE(phantom.ok());
  files.mesh = dir.Path("leg.obj");
  EXPECT_TRUE(WriteMeshFile(phantom->mesh, files.mesh).ok());
  files.skeleton = dir.Write("leg.json", SkeletonToJson(phantom->skeleton));
  for (BoneSurface bone : phantom->bones) {
    const Eigen::RowVector3d centroid = bone.mesh.vertices.colwise().mean();
    for (Eigen::Index i = 0; i < bone.mesh.vertices.rows(); ++i) {
      bone.mesh.vertices.row(i) = centroid + bone_scale * (bone.mesh.vertices.row(i) - centroid);
    }
    files.bones.push_back(dir.Path(bone.name + ".obj"));
    EXPECT_TRUE(WriteMeshFile(bone.mesh, files.bones.back()).ok());
  }
  return files;
}

class BoneSurfaceLoadTest : public ServiceTest {
 protected:
  TempDir dir_;
};

TEST_F(BoneSurfaceLoadTest, APhantomListsItsThreeBoneSurfacesWithTheirGeometry) {
  StartServer();
  v1::MeshSummary summary;
  const std::string mesh_id = LoadPhantom(1200, {}, &summary);
  ASSERT_EQ(summary.bone_surfaces_size(), 3);
  EXPECT_EQ(summary.bone_surfaces(0).name(), "femur");
  EXPECT_EQ(summary.bone_surfaces(0).bone(), 0u);
  EXPECT_EQ(summary.bone_surfaces(1).name(), "tibia");
  EXPECT_EQ(summary.bone_surfaces(1).bone(), 1u);
  EXPECT_EQ(summary.bone_surfaces(2).name(), "patella");
  EXPECT_EQ(summary.bone_surfaces(2).blend_bone(), 1);
  EXPECT_DOUBLE_EQ(summary.bone_surfaces(2).blend(), 0.5);
  EXPECT_TRUE(summary.constraints().contacts());
  EXPECT_TRUE(summary.constraints().keep_volume());
  EXPECT_DOUBLE_EQ(summary.constraints().contact_margin(), 1e-3);

  v1::GetMeshInfoResponse info;
  ASSERT_TRUE(client_->GetMeshInfo(mesh_id, /*include_geometry=*/true, &info).ok());
  ASSERT_EQ(info.bone_surfaces_size(), 3);
  for (int s = 0; s < 3; ++s) {
    const v1::BoneSurfaceInfo& surface = info.summary().bone_surfaces(s);
    EXPECT_GT(surface.triangle_count(), 0u);
    EXPECT_EQ(info.bone_surfaces(s).rest_positions().size(), 12u * surface.vertex_count());
    EXPECT_EQ(info.bone_surfaces(s).triangles().size(), 12u * surface.triangle_count());
  }
  ASSERT_TRUE(client_->GetMeshInfo(mesh_id, /*include_geometry=*/false, &info).ok());
  EXPECT_EQ(info.bone_surfaces_size(), 0);  // geometry only on request

  v1::LoadMeshHeader header;
  header.mutable_phantom()->set_vertices(600);
  header.mutable_phantom()->set_without_bones(true);
  ASSERT_TRUE(client_->LoadMesh(header, {}, &summary).ok());
  EXPECT_EQ(summary.bone_surfaces_size(), 0);
}

TEST_F(BoneSurfaceLoadTest, AnUploadsBoneSurfacesAreNamedAfterTheirFiles) {
  StartServer();
  const PhantomFiles files = WritePhantom(dir_, 1200);
  v1::MeshSummary summary;
  const grpc::Status status =
      client_->LoadMeshFiles(files.mesh, files.skeleton, {}, &summary, {}, "",
                             {files.bones[0] + ":0", files.bones[1] + ":knee"});
  ASSERT_TRUE(status.ok()) << status.error_message();
  ASSERT_EQ(summary.bone_surfaces_size(), 2);
  EXPECT_EQ(summary.bone_surfaces(0).name(), "femur");
  EXPECT_EQ(summary.bone_surfaces(0).bone(), 0u);
  EXPECT_EQ(summary.bone_surfaces(1).name(), "tibia");
  EXPECT_EQ(summary.bone_surfaces(1).bone(), 1u);  // the bone that starts at the knee
  EXPECT_EQ(summary.bone_surfaces(1).blend_bone(), -1);
}

TEST_F(BoneSurfaceLoadTest, ABoneTheRestSkinEntersIsInvalidArgumentNamingIt) {
  StartServer();
  // The femur three times its size reaches through the thigh's skin; on the shin's bone none of
  // that skin is its own rigid zone.
  const PhantomFiles files = WritePhantom(dir_, 1200, /*bone_scale=*/3);
  v1::MeshSummary summary;
  const grpc::Status status = client_->LoadMeshFiles(files.mesh, files.skeleton, {}, &summary, {},
                                                     "", {files.bones[0] + ":1"});
  EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT) << status.error_message();
  EXPECT_THAT(status.error_message(), HasSubstr("femur"));
  ExpectBackgroundStreamAlive();
  // The server goes on loading.
  EXPECT_FALSE(LoadPhantom(600).empty());
}

TEST_F(BoneSurfaceLoadTest, AnUnknownBoneIsInvalidArgumentNamingIt) {
  StartServer();
  const PhantomFiles files = WritePhantom(dir_, 800);
  v1::MeshSummary summary;
  const grpc::Status status = client_->LoadMeshFiles(files.mesh, files.skeleton, {}, &summary, {},
                                                     "", {files.bones[0] + ":elbow"});
  EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_THAT(status.error_message(), HasSubstr("elbow"));
  EXPECT_THAT(status.error_message(), HasSubstr("femur"));

  // A surface that is no mesh, and a blend bone that is not the bone's child.
  v1::LoadMeshHeader header;
  v1::UploadSource* upload = header.mutable_upload();
  upload->set_format(v1::MESH_FORMAT_OBJ);
  upload->set_skeleton_format(v1::SKELETON_FORMAT_JSON);
  ASSERT_TRUE(client::AddBoneSurfaceFile(files.bones[2] + ":1", upload).ok());
  upload->mutable_bone_surfaces(0)->set_blend_bone("0");
  upload->mutable_bone_surfaces(0)->set_blend(0.5);
  std::string mesh_bytes, skeleton_bytes;
  {
    std::ifstream mesh(files.mesh), skeleton(files.skeleton);
    mesh_bytes.assign(std::istreambuf_iterator<char>(mesh), {});
    skeleton_bytes.assign(std::istreambuf_iterator<char>(skeleton), {});
  }
  upload->set_skeleton(skeleton_bytes);
  const grpc::Status blend = client_->LoadMesh(header, mesh_bytes, &summary);
  EXPECT_EQ(blend.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_THAT(blend.error_message(), HasSubstr("patella"));
  upload->mutable_bone_surfaces(0)->set_mesh("not a mesh");
  const grpc::Status garbage = client_->LoadMesh(header, mesh_bytes, &summary);
  EXPECT_EQ(garbage.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  ExpectBackgroundStreamAlive();
}

TEST_F(BoneSurfaceLoadTest, BoneSurfacesOverTheirLimitAreResourceExhaustedNamingTheFlag) {
  service::ServerOptions options = TestServerOptions();
  options.limits.max_bone_surface_bytes = 1000;
  StartServer(options);
  const PhantomFiles files = WritePhantom(dir_, 800);
  v1::MeshSummary summary;
  const grpc::Status status = client_->LoadMeshFiles(files.mesh, files.skeleton, {}, &summary, {},
                                                     "", {files.bones[0] + ":0"});
  EXPECT_EQ(status.error_code(), grpc::StatusCode::RESOURCE_EXHAUSTED);
  EXPECT_THAT(status.error_message(), HasSubstr("--max-bone-surface-mb"));
  ExpectBackgroundStreamAlive();
}

}  // namespace
}  // namespace deform::test_support
