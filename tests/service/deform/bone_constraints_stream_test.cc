// The Deform stream on a mesh with bone surfaces: every frame carries the surfaces' transforms and
// its constraint report, the skin stays out of the bones at a deep flexion, and constraints turned
// off give the model's own frames. Every body runs over both transports.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "core/base/pose_spec.h"
#include "core/geometry/pose.h"
#include "core/io/mesh_io.h"
#include "core/io/phantom.h"
#include "core/io/skeleton_io.h"
#include "core/model/deformation_model.h"
#include "tests/service/support/service_fixture.h"
#include "tests/service/support/temp_dir.h"

namespace deform::test_support {
namespace {

constexpr int kVertices = 2000;

// The unconstrained model's frame of the default phantom for `knee_degrees` of flexion, and the
// diagonal.
struct ModelFrame {
  Positions positions;
  double diagonal = 0;
};

ModelFrame UnconstrainedFrame(double knee_degrees) {
  auto phantom = MakeKneePhantom(kVertices);
  EXPECT_TRUE(phantom.ok());
  auto model = DeformationModel::Build(phantom->mesh, phantom->skeleton, ModelOptions::Paper());
  EXPECT_TRUE(model.ok()) << model.status().ToString();
  auto terms = ParsePoseSpec("knee:flexion:" + std::to_string(knee_degrees), (*model)->skeleton());
  EXPECT_TRUE(terms.ok());
  Pose pose;
  EXPECT_TRUE(PoseFromTerms((*model)->skeleton(), *terms, &pose).ok());
  DeformScratch scratch = (*model)->MakeScratch();
  (*model)->Deform(*(*model)->default_factorization(), pose, &scratch);
  return {scratch.positions(), (*model)->bounding_box_diagonal()};
}

// The phantom as files with its femur and tibia twice as thick (about their centroids, across the
// bone): still inside the rest skin, but the bent knee's skin enters them.
struct ThickBoneFiles {
  std::string mesh;
  std::string skeleton;
  std::vector<std::string> bones;  // "FILE:BONE"
};

ThickBoneFiles WriteThickBones(const TempDir& dir) {
  ThickBoneFiles files;
  auto phantom = MakeKneePhantom(kVertices);
  EXPECT_TRUE(phantom.ok());
  files.mesh = dir.Path("leg.obj");
  EXPECT_TRUE(WriteMeshFile(phantom->mesh, files.mesh).ok());
  files.skeleton = dir.Write("leg.json", SkeletonToJson(phantom->skeleton));
  for (int b = 0; b < 2; ++b) {
    TriangleMesh bone = phantom->bones[b].mesh;
    const Eigen::RowVector3d centroid = bone.vertices.colwise().mean();
    for (Eigen::Index i = 0; i < bone.vertices.rows(); ++i) {
      for (const int axis : {0, 2}) {
        bone.vertices(i, axis) = centroid[axis] + 2 * (bone.vertices(i, axis) - centroid[axis]);
      }
    }
    const std::string path = dir.Path(phantom->bones[b].name + ".obj");
    EXPECT_TRUE(WriteMeshFile(bone, path).ok());
    files.bones.push_back(path + ":" + std::to_string(phantom->bones[b].bone));
  }
  return files;
}

class BoneConstraintsStreamTest : public ServiceTest,
                                  public ::testing::WithParamInterface<Transport> {
 protected:
  void SetUp() override { transport_ = GetParam(); }

  // The frame answering one knee pose on `mesh_id`.
  v1::DeformFrame FrameAt(const std::string& mesh_id, double knee_degrees) {
    StreamRecorder recorder(/*keep_positions=*/true);
    auto stream = OpenStream(mesh_id, recorder.Callbacks());
    EXPECT_TRUE(stream->SendPose(KneePose(1, knee_degrees)));
    EXPECT_TRUE(recorder.WaitForFrameWithSequence(1));
    stream->Close();
    EXPECT_TRUE(stream->Wait().ok());
    return recorder.last_frame();
  }
};

INSTANTIATE_TEST_SUITE_P(Transports, BoneConstraintsStreamTest,
                         ::testing::Values(Transport::kGrpc, Transport::kWebSocket), TransportName);

TEST_P(BoneConstraintsStreamTest, AtKneeFlexion120NoSkinIsLeftInsideABone) {
  StartServer();
  v1::MeshSummary summary;
  const std::string mesh_id = LoadPhantom(kVertices, {}, &summary);
  ASSERT_EQ(summary.bone_surfaces_size(), 3);
  const v1::DeformFrame frame = FrameAt(mesh_id, 120);
  ASSERT_EQ(frame.bone_transforms().size(), 3u * 12 * sizeof(float));
  ASSERT_TRUE(frame.has_constraints());
  EXPECT_EQ(frame.constraints().penetrating_after(), 0u)
      << "before: " << frame.constraints().penetrating_before();
  EXPECT_EQ(frame.constraints().max_depth_after(), 0.0);
  EXPECT_FALSE(frame.constraints().unresolved());
  EXPECT_LT(std::abs(frame.constraints().volume_change()), 2e-4);
  EXPECT_GE(frame.timings().constraint_ms(), 0.0);

  // The femur stays (the hip is at rest); the tibia turns by the knee's 120 degrees: the trace
  // of its rotation is 1 + 2 cos 120 = 0.
  const std::vector<client::BoneSurfaceMotion> motions =
      client::DecodeBoneTransforms(frame.bone_transforms());
  ASSERT_EQ(motions.size(), 3u);
  const float* femur = motions[0].rotation;
  EXPECT_NEAR(femur[0] + femur[4] + femur[8], 3.0, 1e-5);
  const float* tibia = motions[1].rotation;
  EXPECT_NEAR(tibia[0] + tibia[4] + tibia[8], 0.0, 1e-5);
  ExpectBackgroundStreamAlive();
}

TEST_P(BoneConstraintsStreamTest, SkinThatEntersABoneIsPushedOutByContacts) {
  StartServer();
  TempDir dir;
  const ThickBoneFiles files = WriteThickBones(dir);
  v1::MethodOptions off;
  off.mutable_constraints()->set_contacts(false);
  v1::MeshSummary summary;
  ASSERT_TRUE(
      client_->LoadMeshFiles(files.mesh, files.skeleton, off, &summary, {}, "", files.bones).ok());
  const v1::FrameConstraints free = FrameAt(summary.mesh_id(), 120).constraints();
  ASSERT_GT(free.penetrating_after(), 0u) << "the thick bones no longer reach the bent skin";
  EXPECT_TRUE(free.unresolved());
  EXPECT_EQ(free.contacts(), 0u);

  const grpc::Status loaded =
      client_->LoadMeshFiles(files.mesh, files.skeleton, {}, &summary, {}, "", files.bones);
  ASSERT_TRUE(loaded.ok()) << loaded.error_message();
  // With contacts the model is built for them (the skin the bones reach is unanchored:
  // bone_reach.h), so its frame before the contacts differs from the one without.
  const v1::FrameConstraints held = FrameAt(summary.mesh_id(), 120).constraints();
  EXPECT_GT(held.penetrating_before(), 0u);
  EXPECT_GT(held.contacts(), 0u);
  EXPECT_LT(held.penetrating_after(), held.penetrating_before());
  EXPECT_LT(held.penetrating_after(), free.penetrating_after());
  ExpectBackgroundStreamAlive();
}

TEST_P(BoneConstraintsStreamTest, ConstraintsOffGiveTheUnconstrainedModelsFrames) {
  StartServer();
  v1::MethodOptions options;
  options.mutable_constraints()->set_contacts(false);
  options.mutable_constraints()->set_keep_volume(false);
  v1::MeshSummary summary;
  const std::string mesh_id = LoadPhantom(kVertices, options, &summary);
  EXPECT_FALSE(summary.constraints().contacts());
  EXPECT_FALSE(summary.constraints().keep_volume());
  const v1::DeformFrame frame = FrameAt(mesh_id, 120);
  const ModelFrame model = UnconstrainedFrame(120);
  const std::vector<float> positions = client::DecodePositions(frame.positions());
  ASSERT_EQ(positions.size(), static_cast<std::size_t>(model.positions.size()));
  double worst = 0;
  for (Eigen::Index i = 0; i < model.positions.rows(); ++i) {
    for (int c = 0; c < 3; ++c) {
      worst = std::max(worst, std::abs(positions[3 * i + c] - model.positions(i, c)));
    }
  }
  EXPECT_LE(worst, 1e-6 * model.diagonal);
  // Still measured, never corrected.
  EXPECT_EQ(frame.bone_transforms().size(), 3u * 12 * sizeof(float));
  EXPECT_EQ(frame.constraints().penetrating_after(), frame.constraints().penetrating_before());
  EXPECT_EQ(frame.constraints().contacts(), 0u);
  EXPECT_EQ(frame.constraints().unresolved(), frame.constraints().penetrating_after() > 0);
  ExpectBackgroundStreamAlive();
}

TEST_P(BoneConstraintsStreamTest, APhantomWithoutBonesKeepsItsVolumeAndSendsNoTransforms) {
  StartServer();
  v1::LoadMeshHeader header;
  header.mutable_phantom()->set_vertices(kVertices);
  header.mutable_phantom()->set_without_bones(true);
  v1::MeshSummary summary;
  ASSERT_TRUE(client_->LoadMesh(header, {}, &summary).ok());
  const v1::DeformFrame frame = FrameAt(summary.mesh_id(), 90);
  EXPECT_TRUE(frame.bone_transforms().empty());
  ASSERT_TRUE(frame.has_constraints());
  EXPECT_EQ(frame.constraints().penetrating_before(), 0u);
  EXPECT_LT(std::abs(frame.constraints().volume_change()), 2e-4);
}

}  // namespace
}  // namespace deform::test_support
