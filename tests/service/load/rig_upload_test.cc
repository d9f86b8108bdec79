// Rigs over gRPC: a skinned glTF written by the test, and the same mesh, skeleton and weights
// uploaded as OBJ + JSON + CSV, deform alike (frames in the glTF file's own vertex order, seams
// included); the summary says where the binding came from, carries the bones and the warnings.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <iterator>
#include <optional>

#include "core/io/gltf_writer.h"
#include "core/io/mesh_io.h"
#include "core/io/phantom.h"
#include "core/io/skeleton_io.h"
#include "core/model/deformation_model.h"
#include "service/context/service_context.h"
#include "tests/service/support/service_fixture.h"

namespace deform {
namespace {

using ::testing::HasSubstr;

class RigUploadTest : public test_support::ServiceTest {};

// The positions of the frame of pose `spec` (decoded by the library from `encoding`).
std::vector<float> FrameFor(client::DeformClient& client, const std::string& mesh_id,
                            const std::string& spec,
                            v1::FrameEncoding encoding = v1::FRAME_ENCODING_FLOAT32) {
  test_support::StreamRecorder recorder(/*keep_positions=*/true);
  client::DeformClient::StreamOptions options;
  options.encoding = encoding;
  auto stream = client.OpenStream(mesh_id, recorder.Callbacks(), options);
  v1::PoseUpdate pose;
  std::string error;
  EXPECT_TRUE(client::ParsePoseAngles(spec, &pose, &error)) << error;
  pose.set_sequence(1);
  EXPECT_TRUE(stream->SendPose(pose));
  EXPECT_TRUE(recorder.WaitForFrameWithSequence(1));
  stream->Close();
  EXPECT_TRUE(stream->Wait().ok());
  return client::DecodePositions(recorder.last_frame().positions());
}

// The phantom's harmonic binding as skinning weights (the CSV text and the core's SkinWeights).
std::pair<SkinWeights, std::string> PhantomWeights(const KneePhantom& phantom) {
  auto model = DeformationModel::Build(phantom.mesh, phantom.skeleton, ModelOptions::Paper());
  EXPECT_TRUE(model.ok());
  const BoneWeights& h = (*model)->bone_weights();
  SkinWeights weights;
  weights.num_bones = phantom.skeleton.num_bones();
  std::string csv = "vertex,bone,weight\n";
  for (int i = 0; i < phantom.mesh.num_vertices(); ++i) {
    std::vector<int> bones;
    std::vector<double> values;
    for (int e = h.offsets[i]; e < h.offsets[i + 1]; ++e) {
      bones.push_back(h.bones[e]);
      values.push_back(h.weights[e]);
      char line[96];
      std::snprintf(line, sizeof line, "%d,%d,%.17g\n", i, h.bones[e], h.weights[e]);
      csv += line;
    }
    weights.AddVertex(bones, values);
  }
  return {weights, csv};
}

TEST_F(RigUploadTest, GltfRigDeformsLikeTheSameRigAsObjJsonAndWeights) {
  StartServer();
  auto phantom = MakeKneePhantom(600);
  ASSERT_TRUE(phantom.ok());
  const auto [weights, csv] = PhantomWeights(*phantom);
  auto glb = WriteGltf(phantom->mesh, phantom->skeleton, weights, GltfContainer::kGlb);
  ASSERT_TRUE(glb.ok()) << glb.status().ToString();

  v1::LoadMeshHeader gltf_header;
  gltf_header.mutable_upload()->set_format(v1::MESH_FORMAT_GLTF);
  v1::MeshSummary gltf_summary;
  grpc::Status loaded = client_->LoadMesh(gltf_header, *glb, &gltf_summary);
  ASSERT_TRUE(loaded.ok()) << loaded.error_message();
  EXPECT_EQ(gltf_summary.binding(), v1::BINDING_WEIGHTS);
  EXPECT_EQ(gltf_summary.units(), "metre");
  EXPECT_EQ(gltf_summary.bones_size(), phantom->skeleton.num_bones());

  // The same rig as OBJ + the project's JSON skeleton + CSV weights.
  const std::string obj_path = ::testing::TempDir() + "/rig_upload.obj";
  ASSERT_TRUE(WriteMeshFile(phantom->mesh, obj_path).ok());
  std::ifstream obj_file(obj_path);
  const std::string obj((std::istreambuf_iterator<char>(obj_file)), {});
  v1::LoadMeshHeader files_header;
  v1::UploadSource* upload = files_header.mutable_upload();
  upload->set_format(v1::MESH_FORMAT_OBJ);
  upload->set_skeleton_format(v1::SKELETON_FORMAT_JSON);
  upload->set_skeleton(SkeletonToJson(phantom->skeleton));
  upload->set_weights_format(v1::SKIN_WEIGHTS_FORMAT_CSV);
  upload->set_weights(csv);
  v1::MeshSummary files_summary;
  loaded = client_->LoadMesh(files_header, obj, &files_summary);
  ASSERT_TRUE(loaded.ok()) << loaded.error_message();
  EXPECT_EQ(files_summary.binding(), v1::BINDING_WEIGHTS);

  // glTF joints carry no named degrees of freedom: rest-frame axes (flexion is +X).
  const std::string spec = "knee:x:80,knee:y:10";
  const std::vector<float> from_gltf = FrameFor(*client_, gltf_summary.mesh_id(), spec);
  const std::vector<float> from_files = FrameFor(*client_, files_summary.mesh_id(), spec);
  ASSERT_EQ(from_gltf.size(), 3u * gltf_summary.vertex_count());
  ASSERT_EQ(from_files.size(), 3u * phantom->mesh.num_vertices());
  // The written glTF keeps the mesh's vertex order (no seams), so the orders agree.
  ASSERT_EQ(from_gltf.size(), from_files.size());
  const double diagonal = BoundingBoxDiagonal(phantom->mesh.vertices);
  double worst = 0;
  for (std::size_t c = 0; c < from_gltf.size(); ++c) {
    worst = std::max(worst, static_cast<double>(std::abs(from_gltf[c] - from_files[c])));
  }
  EXPECT_LT(worst, 1e-6 * diagonal);
  ExpectBackgroundStreamAlive();
}

// A glTF whose vertex buffer holds vertices no triangle uses (the first, one in the middle, the
// last), as exporters leave them: it loads with a warning; the rest geometry and the frames of
// every encoding give each of them the position of the used vertex before it in the file (the
// first used one, for the first), and GetMeshInfo's triangles name only used vertices.
TEST_F(RigUploadTest, GltfVerticesNoTriangleUsesFollowTheUsedVertexBeforeThem) {
  StartServer();
  auto phantom = MakeKneePhantom(600);
  ASSERT_TRUE(phantom.ok());
  const auto [weights, csv] = PhantomWeights(*phantom);
  const int n = phantom->mesh.num_vertices();
  // File order: a stray, vertices [0, n / 2), a stray, [n / 2, n), a stray.
  const std::vector<int> strays = {0, n / 2 + 1, n + 2};
  TriangleMesh loose;
  loose.vertices.resize(n + 3, 3);
  SkinWeights loose_weights;
  loose_weights.num_bones = weights.num_bones;
  std::vector<int> file_of(static_cast<std::size_t>(n));
  for (int f = 0, v = 0; f < n + 3; ++f) {
    if (std::find(strays.begin(), strays.end(), f) != strays.end()) {
      loose.vertices.row(f) = Eigen::RowVector3d(0.5, 0.5, 0.5);  // away from every used vertex
      loose_weights.AddVertex({0}, {1.0});
      continue;
    }
    file_of[static_cast<std::size_t>(v)] = f;
    loose.vertices.row(f) = phantom->mesh.vertices.row(v);
    loose_weights.AddVertex(std::vector<int>(weights.bones.begin() + weights.offsets[v],
                                             weights.bones.begin() + weights.offsets[v + 1]),
                            std::vector<double>(weights.weights.begin() + weights.offsets[v],
                                                weights.weights.begin() + weights.offsets[v + 1]));
    ++v;
  }
  loose.triangles = phantom->mesh.triangles;
  for (Eigen::Index k = 0; k < loose.triangles.size(); ++k) {
    loose.triangles.data()[k] = file_of[static_cast<std::size_t>(loose.triangles.data()[k])];
  }
  auto glb = WriteGltf(loose, phantom->skeleton, loose_weights, GltfContainer::kGlb);
  ASSERT_TRUE(glb.ok()) << glb.status().ToString();
  v1::LoadMeshHeader header;
  header.mutable_upload()->set_format(v1::MESH_FORMAT_GLTF);
  v1::MeshSummary summary;
  const grpc::Status loaded = client_->LoadMesh(header, *glb, &summary);
  ASSERT_TRUE(loaded.ok()) << loaded.error_message();
  EXPECT_EQ(summary.vertex_count(), static_cast<std::uint32_t>(n + 3));
  EXPECT_EQ(summary.solved_vertex_count(), static_cast<std::uint32_t>(n));
  EXPECT_THAT(summary.warnings(), ::testing::Contains(HasSubstr("3 of the file's vertices")));

  // The file vertex whose position each stray takes: the one before it, the next for the first.
  const auto followed = [&](int f) { return f == 0 ? 1 : f - 1; };
  const auto expect_strays_follow = [&](const std::vector<float>& positions, const char* what) {
    ASSERT_EQ(positions.size(), 3u * (n + 3)) << what;
    for (const float value : positions) ASSERT_TRUE(std::isfinite(value)) << what;
    for (const int f : strays) {
      for (int c = 0; c < 3; ++c) {
        EXPECT_EQ(positions[3 * f + c], positions[3 * followed(f) + c])
            << what << ": file vertex " << f;
      }
    }
  };
  v1::GetMeshInfoResponse info;
  ASSERT_TRUE(client_->GetMeshInfo(summary.mesh_id(), true, &info).ok());
  const std::vector<float> rest = client::DecodePositions(info.rest_positions());
  expect_strays_follow(rest, "rest positions");
  for (int v = 0; v < n; ++v) {
    for (int c = 0; c < 3; ++c) {
      EXPECT_FLOAT_EQ(rest[3 * file_of[static_cast<std::size_t>(v)] + c],
                      static_cast<float>(phantom->mesh.vertices(v, c)));
    }
  }
  ASSERT_EQ(info.triangles().size(), 4u * 3 * phantom->mesh.num_triangles());
  for (std::size_t k = 0; k < info.triangles().size() / 4; ++k) {
    std::uint32_t vertex = 0;
    std::memcpy(&vertex, info.triangles().data() + 4 * k, 4);  // little-endian hosts
    EXPECT_EQ(vertex, static_cast<std::uint32_t>(loose.triangles.data()[k])) << "corner " << k;
  }
  const std::string spec = "knee:x:80,knee:y:10";
  expect_strays_follow(FrameFor(*client_, summary.mesh_id(), spec), "float32 frame");
  for (const v1::FrameEncoding encoding :
       {v1::FRAME_ENCODING_QUANTIZED, v1::FRAME_ENCODING_PREDICTED}) {
    const std::vector<float> decoded = FrameFor(*client_, summary.mesh_id(), spec, encoding);
    ASSERT_EQ(decoded.size(), 3u * (n + 3)) << "encoding " << encoding;
    for (const float value : decoded) ASSERT_TRUE(std::isfinite(value)) << "encoding " << encoding;
  }
  ExpectBackgroundStreamAlive();
}

TEST_F(RigUploadTest, RigidWeightToleranceChoosesTheRigidZonesOfGivenWeights) {
  StartServer();
  auto phantom = MakeKneePhantom(600);
  ASSERT_TRUE(phantom.ok());
  const std::string csv = PhantomWeights(*phantom).second;
  const std::string obj_path = ::testing::TempDir() + "/rig_tolerance.obj";
  ASSERT_TRUE(WriteMeshFile(phantom->mesh, obj_path).ok());
  std::ifstream obj_file(obj_path);
  const std::string obj((std::istreambuf_iterator<char>(obj_file)), {});
  const auto load = [&](std::optional<double> tolerance, v1::MeshSummary* summary) {
    v1::LoadMeshHeader header;
    v1::UploadSource* upload = header.mutable_upload();
    upload->set_format(v1::MESH_FORMAT_OBJ);
    upload->set_skeleton_format(v1::SKELETON_FORMAT_JSON);
    upload->set_skeleton(SkeletonToJson(phantom->skeleton));
    upload->set_weights_format(v1::SKIN_WEIGHTS_FORMAT_CSV);
    upload->set_weights(csv);
    if (tolerance) header.mutable_options()->set_rigid_weight_tolerance(*tolerance);
    return client_->LoadMesh(header, obj, summary);
  };
  const auto rigid_vertices = [&](const std::string& id, double* tolerance) {
    auto entry = server_->server().context().registry().Find(id);
    EXPECT_TRUE(entry.ok());
    *tolerance = (*entry)->model->options().rigid_weight_tolerance;
    const std::vector<int>& rigid = (*entry)->model->rigid_bones();
    return std::count_if(rigid.begin(), rigid.end(), [](int bone) { return bone >= 0; });
  };
  v1::MeshSummary unset, exact, loose;
  ASSERT_TRUE(load(std::nullopt, &unset).ok());
  ASSERT_TRUE(load(0.0, &exact).ok());
  ASSERT_TRUE(load(0.3, &loose).ok());
  double tolerance = -1;
  const auto unset_count = rigid_vertices(unset.mesh_id(), &tolerance);
  EXPECT_EQ(tolerance, 0.01) << "unset is the default";
  const auto exact_count = rigid_vertices(exact.mesh_id(), &tolerance);
  EXPECT_EQ(tolerance, 0.0) << "0 is a value, not unset";
  const auto loose_count = rigid_vertices(loose.mesh_id(), &tolerance);
  EXPECT_EQ(tolerance, 0.3);
  EXPECT_LE(exact_count, unset_count);
  EXPECT_LT(unset_count, loose_count) << "a looser tolerance makes more of the mesh rigid";

  v1::MeshSummary refused;
  for (const double bad : {0.5, -0.1, std::nan("")}) {
    const grpc::Status status = load(bad, &refused);
    EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT) << bad;
    EXPECT_THAT(status.error_message(), HasSubstr("rigid_weight_tolerance")) << bad;
  }
  ExpectBackgroundStreamAlive();
}

TEST_F(RigUploadTest, GltfUploadRefusesASkeletonBesideIt) {
  StartServer();
  v1::LoadMeshHeader header;
  header.mutable_upload()->set_format(v1::MESH_FORMAT_GLTF);
  header.mutable_upload()->set_skeleton("not wanted");
  v1::MeshSummary summary;
  const grpc::Status status = client_->LoadMesh(header, "glTF", &summary);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_THAT(status.error_message(), HasSubstr("carries its own skeleton"));
}

// The phantom written as a glTF with its bone surfaces as mesh nodes under their joints: they
// come back as the rig's bone surfaces (the patella on its bone alone: glTF has no blend), keep
// the skin out of them when the knee bends, and skip_gltf_bone_nodes leaves them out.
TEST_F(RigUploadTest, AGltfRigsBoneNodesAreItsBoneSurfaces) {
  StartServer();
  auto phantom = MakeKneePhantom(1200);
  ASSERT_TRUE(phantom.ok());
  const auto [weights, csv] = PhantomWeights(*phantom);
  auto glb =
      WriteGltf(phantom->mesh, phantom->skeleton, weights, GltfContainer::kGlb, phantom->bones);
  ASSERT_TRUE(glb.ok()) << glb.status().ToString();
  v1::LoadMeshHeader header;
  header.mutable_upload()->set_format(v1::MESH_FORMAT_GLTF);
  v1::MeshSummary summary;
  grpc::Status loaded = client_->LoadMesh(header, *glb, &summary);
  ASSERT_TRUE(loaded.ok()) << loaded.error_message();
  ASSERT_EQ(summary.bone_surfaces_size(), 3);
  for (int s = 0; s < 3; ++s) {
    const BoneSurface& written = phantom->bones[static_cast<std::size_t>(s)];
    EXPECT_EQ(summary.bone_surfaces(s).name(), written.name);
    EXPECT_EQ(summary.bone_surfaces(s).bone(), static_cast<std::uint32_t>(written.bone));
    EXPECT_EQ(summary.bone_surfaces(s).blend_bone(), -1);
    EXPECT_EQ(summary.bone_surfaces(s).vertex_count(),
              static_cast<std::uint32_t>(written.mesh.num_vertices()));
  }
  for (const std::string& warning : summary.warnings()) {
    EXPECT_EQ(warning.find("not a bone surface"), std::string::npos) << warning;
  }
  test_support::StreamRecorder recorder(/*keep_positions=*/false);
  auto stream = client_->OpenStream(summary.mesh_id(), recorder.Callbacks(), {});
  v1::PoseUpdate pose;
  std::string error;
  ASSERT_TRUE(client::ParsePoseAngles("knee:x:100", &pose, &error)) << error;
  pose.set_sequence(1);
  ASSERT_TRUE(stream->SendPose(pose));
  ASSERT_TRUE(recorder.WaitForFrameWithSequence(1));
  stream->Close();
  EXPECT_TRUE(stream->Wait().ok());
  const v1::DeformFrame frame = recorder.last_frame();  // a copy: last_frame() returns one
  const v1::FrameConstraints& constraints = frame.constraints();
  EXPECT_EQ(constraints.penetrating_after(), 0u);
  EXPECT_FALSE(constraints.unresolved());

  header.mutable_upload()->set_skip_gltf_bone_nodes(true);
  loaded = client_->LoadMesh(header, *glb, &summary);
  ASSERT_TRUE(loaded.ok()) << loaded.error_message();
  EXPECT_EQ(summary.bone_surfaces_size(), 0);
  ExpectBackgroundStreamAlive();
}

TEST_F(RigUploadTest, SummaryCarriesBonesAndTheAutomaticBinding) {
  StartServer();
  v1::MeshSummary summary;
  LoadPhantom(500, {}, &summary);
  EXPECT_EQ(summary.binding(), v1::BINDING_THROUGH_BODY);
  EXPECT_EQ(summary.bones_size(), 2);
  EXPECT_EQ(summary.bones(1).parent_bone(), 0);
  EXPECT_TRUE(summary.warnings().empty());
  EXPECT_EQ(summary.solved_vertex_count(), summary.vertex_count());
}

}  // namespace
}  // namespace deform
