#include "core/io/rig_import.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "core/io/gltf_writer.h"
#include "tests/core/io/gltf_test_util.h"

namespace deform {
namespace {

using gltf_test::ChainRig;
using gltf_test::GltfBuilder;
using gltf_test::PrimitiveData;
using gltf_test::RigidTubePrimitive;
using gltf_test::TestRig;
using gltf_test::Tube;

// The weight of the bone from joint `head` to joint `tail` (by name) at `vertex`.
double BoneWeight(const Skeleton& skeleton, const SkinWeights& weights, int vertex,
                  const std::string& head, const std::string& tail) {
  double total = 0;
  for (int e = weights.offsets[vertex]; e < weights.offsets[vertex + 1]; ++e) {
    const Bone& bone = skeleton.bone(weights.bones[e]);
    if (skeleton.joint(bone.head_joint).name == head &&
        skeleton.joint(bone.tail_joint).name == tail) {
      total += weights.weights[e];
    }
  }
  return total;
}

void ExpectRefused(const std::string& bytes, StatusCode code, const std::string& needle) {
  auto rig = ReadGltf(bytes);
  ASSERT_FALSE(rig.ok()) << "accepted; expected: " << needle;
  EXPECT_EQ(rig.status().code(), code) << rig.status().ToString();
  EXPECT_NE(rig.status().message().find(needle), std::string::npos)
      << "'" << needle << "' not in: " << rig.status().message();
}

// The same rig back: positions, joints and weights to 1e-6, vertex i of the file = vertex i.
void ExpectSameRig(const TestRig& original, const RigImport& read) {
  ASSERT_EQ(read.mesh.num_vertices(), original.mesh.num_vertices());
  ASSERT_EQ(read.mesh.num_triangles(), original.mesh.num_triangles());
  EXPECT_LT((read.mesh.vertices - original.mesh.vertices).cwiseAbs().maxCoeff(), 1e-6);
  EXPECT_EQ(read.mesh.triangles, original.mesh.triangles);
  ASSERT_EQ(read.skeleton.num_joints(), original.skeleton.num_joints());
  ASSERT_EQ(read.skeleton.num_bones(), original.skeleton.num_bones());
  for (int j = 0; j < original.skeleton.num_joints(); ++j) {
    EXPECT_EQ(read.skeleton.joint(j).name, original.skeleton.joint(j).name);
    EXPECT_LT(
        (read.skeleton.joint(j).rest_position - original.skeleton.joint(j).rest_position).norm(),
        1e-6);
  }
  for (int b = 0; b < original.skeleton.num_bones(); ++b) {
    EXPECT_EQ(read.skeleton.bone(b).head_joint, original.skeleton.bone(b).head_joint);
    EXPECT_EQ(read.skeleton.bone(b).tail_joint, original.skeleton.bone(b).tail_joint);
  }
  auto expected = NormalizeSkinWeights(original.weights, original.mesh.num_vertices(),
                                       original.skeleton.num_bones());
  ASSERT_TRUE(expected.ok());
  for (int v = 0; v < original.mesh.num_vertices(); ++v) {
    for (int b = 0; b < original.skeleton.num_bones(); ++b) {
      const Bone& bone = original.skeleton.bone(b);
      const std::string head = original.skeleton.joint(bone.head_joint).name;
      const std::string tail = original.skeleton.joint(bone.tail_joint).name;
      EXPECT_NEAR(BoneWeight(read.skeleton, read.weights, v, head, tail),
                  BoneWeight(original.skeleton, *expected, v, head, tail), 1e-6)
          << "vertex " << v << " bone " << b;
    }
  }
  for (int v = 0; v < original.mesh.num_vertices(); ++v) {
    EXPECT_EQ(read.file_vertex_to_mesh[static_cast<std::size_t>(v)], v);
  }
  EXPECT_EQ(read.units, "metre");
  EXPECT_EQ(read.up_axis, "+Y");
}

TEST(ReadGltf, RoundTripsAWrittenRigAsGltfAndGlb) {
  const TestRig tube = Tube();
  for (GltfContainer container : {GltfContainer::kGltf, GltfContainer::kGlb}) {
    auto bytes = WriteGltf(tube.mesh, tube.skeleton, tube.weights, container);
    ASSERT_TRUE(bytes.ok()) << bytes.status().ToString();
    EXPECT_EQ(bytes->substr(0, 4) == "glTF", container == GltfContainer::kGlb);
    auto read = ReadGltf(*bytes);
    ASSERT_TRUE(read.ok()) << read.status().ToString();
    ExpectSameRig(tube, *read);
  }
}

TEST(ReadGltf, RoundTripsThroughFiles) {
  const TestRig tube = Tube();
  const std::string path =
      (std::filesystem::temp_directory_path() / "deform_rig_import_test.glb").string();
  ASSERT_TRUE(WriteGltfFile(path, tube.mesh, tube.skeleton, tube.weights).ok());
  auto read = ReadGltfFile(path);
  std::filesystem::remove(path);
  ASSERT_TRUE(read.ok()) << read.status().ToString();
  ExpectSameRig(tube, *read);
  EXPECT_EQ(ReadGltfFile(path).status().code(), StatusCode::kNotFound);
  EXPECT_TRUE(IsGltfPath("a/b/rig.GLB"));
  EXPECT_TRUE(IsGltfPath("rig.gltf"));
  EXPECT_FALSE(IsGltfPath("rig.obj"));
}

TEST(ReadGltf, WeldsSeamSplitVerticesBack) {
  // Split the tube along its seam (column 0), as an exporter does at a UV seam: the last column's
  // triangles use copies of column 0's vertices.
  const TestRig tube = Tube(8, 5);
  TestRig split = tube;
  const int sides = 8, rings = 5, n = tube.mesh.num_vertices();
  split.mesh.vertices.conservativeResize(n + rings, 3);
  for (int r = 0; r < rings; ++r) {
    split.mesh.vertices.row(n + r) = tube.mesh.vertices.row(r * sides);
    const double w = gltf_test::LowerBoneWeight(tube.mesh.vertices(r * sides, 1));
    split.weights.AddVertex({0, 1}, {w, 1 - w});
  }
  for (Eigen::Index t = 0; t < split.mesh.triangles.rows(); ++t) {
    bool last_column = false;
    for (int c = 0; c < 3; ++c) last_column |= split.mesh.triangles(t, c) % sides == sides - 1;
    if (!last_column) continue;
    for (int c = 0; c < 3; ++c) {
      int& v = split.mesh.triangles(t, c);
      if (v % sides == 0) v = n + v / sides;
    }
  }
  auto bytes = WriteGltf(split.mesh, split.skeleton, split.weights, GltfContainer::kGlb);
  ASSERT_TRUE(bytes.ok()) << bytes.status().ToString();
  auto read = ReadGltf(*bytes);
  ASSERT_TRUE(read.ok()) << read.status().ToString();
  ASSERT_EQ(read->mesh.num_vertices(), n);
  ASSERT_EQ(read->file_vertex_to_mesh.size(), static_cast<std::size_t>(n + rings));
  for (int v = 0; v < n; ++v) EXPECT_EQ(read->file_vertex_to_mesh[static_cast<std::size_t>(v)], v);
  for (int r = 0; r < rings; ++r) {
    EXPECT_EQ(read->file_vertex_to_mesh[static_cast<std::size_t>(n + r)], r * sides);
  }
  EXPECT_EQ(read->mesh.triangles, tube.mesh.triangles);  // the seam is closed again
}

TEST(ReadGltf, ConcatenatesPrimitivesOfEveryAccessorForm) {
  // Two primitives: the tube's lower and upper halves of triangles, each with its own copy of all
  // vertices. The first is indexed with interleaved positions (stride 16) and byte weights; the
  // second is an unindexed triangle soup with unsigned-short weights.
  const TestRig tube = Tube(6, 4);
  const PrimitiveData all = RigidTubePrimitive(tube);
  const std::size_t half = all.indices.size() / 2;
  GltfBuilder builder = ChainRig({{0, 0, 0}, {0, 1, 0}, {0, 2, 0}}, {});
  // Primitive 0.
  std::vector<float> interleaved;
  for (int v = 0; v < all.vertex_count(); ++v) {
    interleaved.insert(interleaved.end(), all.positions.begin() + 3 * v,
                       all.positions.begin() + 3 * v + 3);
    interleaved.push_back(-7.0f);  // padding the stride skips
  }
  std::vector<std::uint8_t> byte_weights;
  for (float w : all.weights) byte_weights.push_back(static_cast<std::uint8_t>(w * 255));
  std::vector<std::uint16_t> lower_indices(all.indices.begin(), all.indices.begin() + half);
  nlohmann::json first = {
      {"attributes",
       {{"POSITION", builder.AddAccessor(gltf_test::Bytes(interleaved), gltf_test::kFloat, "VEC3",
                                         all.vertex_count(), false, 16)},
        {"JOINTS_0", builder.AddAccessor(gltf_test::Bytes(all.joints), gltf_test::kUnsignedByte,
                                         "VEC4", all.vertex_count())},
        {"WEIGHTS_0", builder.AddAccessor(gltf_test::Bytes(byte_weights), gltf_test::kUnsignedByte,
                                          "VEC4", all.vertex_count(), true)}}},
      {"indices", builder.AddAccessor(gltf_test::Bytes(lower_indices), gltf_test::kUnsignedShort,
                                      "SCALAR", static_cast<int>(half))},
      {"mode", 4}};
  // Primitive 1: the upper half as a soup.
  PrimitiveData soup;
  std::vector<std::uint16_t> short_weights;
  for (std::size_t k = half; k < all.indices.size(); ++k) {
    const std::uint32_t v = all.indices[k];
    soup.positions.insert(soup.positions.end(), all.positions.begin() + 3 * v,
                          all.positions.begin() + 3 * v + 3);
    soup.joints.insert(soup.joints.end(), all.joints.begin() + 4 * v,
                       all.joints.begin() + 4 * v + 4);
    for (int c = 0; c < 4; ++c) {
      short_weights.push_back(static_cast<std::uint16_t>(all.weights[4 * v + c] * 65535));
    }
  }
  nlohmann::json second = {
      {"attributes",
       {{"POSITION", builder.AddAccessor(gltf_test::Bytes(soup.positions), gltf_test::kFloat,
                                         "VEC3", soup.vertex_count())},
        {"JOINTS_0", builder.AddAccessor(gltf_test::Bytes(soup.joints), gltf_test::kUnsignedByte,
                                         "VEC4", soup.vertex_count())},
        {"WEIGHTS_0",
         builder.AddAccessor(gltf_test::Bytes(short_weights), gltf_test::kUnsignedShort, "VEC4",
                             soup.vertex_count(), true)}}}};
  builder.doc()["meshes"] = {{{"primitives", {first, second}}}};
  auto read = ReadGltf(builder.ToGltf());
  ASSERT_TRUE(read.ok()) << read.status().ToString();
  EXPECT_EQ(read->mesh.num_vertices(), tube.mesh.num_vertices());
  EXPECT_EQ(read->mesh.num_triangles(), tube.mesh.num_triangles());
  EXPECT_EQ(read->file_vertex_to_mesh.size(),
            static_cast<std::size_t>(all.vertex_count() + soup.vertex_count()));
  // Each file vertex maps to a mesh vertex at its own position: primitive 0's copies of the
  // upper vertices, which its triangles do not use, are welded to the soup's, which use them.
  EXPECT_TRUE(read->unused_file_vertices.empty());
  for (std::size_t f = 0; f < read->file_vertex_to_mesh.size(); ++f) {
    const int m = read->file_vertex_to_mesh[f];
    ASSERT_GE(m, 0);
    const float* p = f < static_cast<std::size_t>(all.vertex_count())
                         ? &all.positions[3 * f]
                         : &soup.positions[3 * (f - all.vertex_count())];
    for (int c = 0; c < 3; ++c) EXPECT_FLOAT_EQ(read->mesh.vertices(m, c), p[c]);
  }
}

// A primitive whose vertex buffer holds vertices no triangle uses (first, in the middle, last):
// the mesh drops them, and in the file's order each follows the used vertex before it (those
// before every used vertex, the first used one), so every file vertex has a mesh vertex.
TEST(ReadGltf, VerticesNoTriangleUsesFollowTheUsedVertexBeforeThem) {
  const TestRig tube = Tube(6, 4);
  const PrimitiveData tight = RigidTubePrimitive(tube);
  const int n = tight.vertex_count();
  // File order: two strays, the tube's first half, a stray, the second half, a stray.
  PrimitiveData loose;
  std::vector<int> file_of_tube_vertex(static_cast<std::size_t>(n));
  const auto add_vertex = [&](const PrimitiveData& from, int v) {
    loose.positions.insert(loose.positions.end(), from.positions.begin() + 3 * v,
                           from.positions.begin() + 3 * v + 3);
    loose.joints.insert(loose.joints.end(), from.joints.begin() + 4 * v,
                        from.joints.begin() + 4 * v + 4);
    loose.weights.insert(loose.weights.end(), from.weights.begin() + 4 * v,
                         from.weights.begin() + 4 * v + 4);
  };
  PrimitiveData stray;  // far from the tube, where no tube vertex is
  stray.positions = {5.0f, 5.0f, 5.0f};
  stray.joints = {0, 0, 0, 0};
  stray.weights = {1.0f, 0.0f, 0.0f, 0.0f};
  std::vector<bool> is_stray;
  for (int v = 0; v < n; ++v) {
    if (v == 0) {
      add_vertex(stray, 0);
      add_vertex(stray, 0);
      is_stray.insert(is_stray.end(), {true, true});
    }
    if (v == n / 2) {
      add_vertex(stray, 0);
      is_stray.push_back(true);
    }
    file_of_tube_vertex[static_cast<std::size_t>(v)] = loose.vertex_count();
    add_vertex(tight, v);
    is_stray.push_back(false);
  }
  add_vertex(stray, 0);
  is_stray.push_back(true);
  for (const std::uint32_t v : tight.indices) {
    loose.indices.push_back(static_cast<std::uint32_t>(file_of_tube_vertex[v]));
  }
  GltfBuilder builder = ChainRig({{0, 0, 0}, {0, 1, 0}, {0, 2, 0}}, {loose});
  auto read = ReadGltf(builder.ToGlb());
  ASSERT_TRUE(read.ok()) << read.status().ToString();
  ASSERT_EQ(read->mesh.num_vertices(), n);
  ASSERT_EQ(read->file_vertex_to_mesh.size(), is_stray.size());
  std::vector<int> strays;
  for (std::size_t f = 0; f < is_stray.size(); ++f) {
    if (is_stray[f]) strays.push_back(static_cast<int>(f));
  }
  EXPECT_EQ(read->unused_file_vertices, strays);
  EXPECT_EQ(strays.size(), 4u);
  const std::vector<int>& map = read->file_vertex_to_mesh;
  for (int v = 0; v < n; ++v) {
    const int m = map[static_cast<std::size_t>(file_of_tube_vertex[static_cast<std::size_t>(v)])];
    for (int c = 0; c < 3; ++c)
      EXPECT_FLOAT_EQ(read->mesh.vertices(m, c), tube.mesh.vertices(v, c));
  }
  const int first_used = file_of_tube_vertex[0];
  for (std::size_t f = 0; f < map.size(); ++f) {
    if (!is_stray[f]) continue;
    const int followed =
        static_cast<int>(f) < first_used ? map[static_cast<std::size_t>(first_used)] : map[f - 1];
    EXPECT_EQ(map[f], followed) << "file vertex " << f;
  }
  EXPECT_EQ(map.back(), map[map.size() - 2]);
}

TEST(ReadGltf, GivesALeafJointWithWeightsAnEndBone) {
  // Two joints; the upper vertices follow joint1, which heads no bone.
  const TestRig tube = Tube();
  GltfBuilder builder = ChainRig({{0, 0, 0}, {0, 1, 0}}, {RigidTubePrimitive(tube)});
  auto read = ReadGltf(builder.ToGltf());
  ASSERT_TRUE(read.ok()) << read.status().ToString();
  ASSERT_EQ(read->skeleton.num_joints(), 3);
  EXPECT_EQ(read->skeleton.joint(2).name, "joint1_end");
  EXPECT_LT((read->skeleton.joint(2).rest_position - Eigen::Vector3d(0, 1.5, 0)).norm(), 1e-12);
  ASSERT_EQ(read->skeleton.num_bones(), 2);
  const int top = read->mesh.num_vertices() - 1;  // y = 2
  EXPECT_DOUBLE_EQ(BoneWeight(read->skeleton, read->weights, top, "joint1", "joint1_end"), 1.0);
  EXPECT_DOUBLE_EQ(BoneWeight(read->skeleton, read->weights, 0, "joint0", "joint1"), 1.0);
}

TEST(ReadGltf, MergesJointsAtTheSamePlace) {
  // joint1 sits exactly on joint0 (a twist joint); its weights go to joint0's bone to joint2.
  const TestRig tube = Tube();
  GltfBuilder builder =
      ChainRig({{0, 0, 0}, {0, 0, 0}, {0, 1, 0}, {0, 2, 0}}, {RigidTubePrimitive(tube)});
  auto read = ReadGltf(builder.ToGltf());
  ASSERT_TRUE(read.ok()) << read.status().ToString();
  ASSERT_EQ(read->skeleton.num_joints(), 3);
  EXPECT_EQ(read->skeleton.joint(0).name, "joint0");
  EXPECT_EQ(read->skeleton.joint(1).name, "joint2");
  EXPECT_EQ(read->skeleton.num_bones(), 2);  // joint0 -> joint2 -> joint3
  // The rigid tube's weights name joints 0 and 1 (= joint0 and the merged joint1): all on bone 0.
  for (int v = 0; v < read->mesh.num_vertices(); ++v) {
    EXPECT_DOUBLE_EQ(BoneWeight(read->skeleton, read->weights, v, "joint0", "joint2"), 1.0);
  }
}

TEST(ReadGltf, ReadsJointsFromInverseBindMatricesOrNodeTransforms) {
  // Joints under a non-joint node that moves them by (1, 0, 0); a mesh node with its own
  // translation (ignored, as glTF says for skinned meshes).
  const TestRig tube = Tube();
  GltfBuilder builder = ChainRig({{-1, 0, 0}, {-1, 1, 0}, {-1, 1, 0}}, {RigidTubePrimitive(tube)});
  builder.doc()["nodes"][2]["translation"] = {0, 1, 0};  // joint2 at (0, 2, 0) relative to world
  const int group =
      builder.AddNode({{"name", "armature"}, {"translation", {1, 0, 0}}, {"children", {0}}});
  builder.doc()["nodes"][3]["translation"] = {5, 0, 0};  // the mesh node
  builder.doc()["scenes"] = {{{"nodes", {group, 3}}}};
  auto from_nodes = ReadGltf(builder.ToGltf());
  ASSERT_TRUE(from_nodes.ok()) << from_nodes.status().ToString();
  EXPECT_LT((from_nodes->skeleton.joint(0).rest_position - Eigen::Vector3d(0, 0, 0)).norm(), 1e-12);
  EXPECT_LT((from_nodes->skeleton.joint(2).rest_position - Eigen::Vector3d(0, 2, 0)).norm(), 1e-12);
  EXPECT_LT((from_nodes->mesh.vertices - tube.mesh.vertices).cwiseAbs().maxCoeff(), 1e-6);
  // Inverse bind matrices take precedence: joints at (0, 0, 0), (0, 0.5, 0), (0, 2, 0).
  std::vector<float> matrices;
  for (float y : {0.0f, 0.5f, 2.0f}) {
    const std::vector<float> m = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, -y, 0, 1};
    matrices.insert(matrices.end(), m.begin(), m.end());
  }
  builder.doc()["skins"][0]["inverseBindMatrices"] =
      builder.AddAccessor(gltf_test::Bytes(matrices), gltf_test::kFloat, "MAT4", 3);
  auto from_binds = ReadGltf(builder.ToGlb());
  ASSERT_TRUE(from_binds.ok()) << from_binds.status().ToString();
  EXPECT_LT((from_binds->skeleton.joint(1).rest_position - Eigen::Vector3d(0, 0.5, 0)).norm(),
            1e-7);
}

// The tube moved by `offset` and shrunk by `scale` about its axis (a second piece: eyes, a strap).
PrimitiveData MovedTubePrimitive(const TestRig& tube, const Eigen::Vector3d& offset, double scale) {
  PrimitiveData data = RigidTubePrimitive(tube);
  for (std::size_t v = 0; v < data.positions.size() / 3; ++v) {
    for (int c = 0; c < 3; ++c) {
      float& x = data.positions[3 * v + static_cast<std::size_t>(c)];
      x = static_cast<float>((c == 1 ? x : scale * x) + offset[c]);
    }
  }
  return data;
}

// A skin over the chain's three joints (nodes 0, 1, 2) listed in `order`, with inverse bind
// matrices for joints at y = 0, 1, 2 whose bind space is moved by `shift` (the mesh's positions
// are then given relative to that shift).
nlohmann::json ShiftedSkin(GltfBuilder* builder, const std::vector<int>& order,
                           const Eigen::Vector3d& shift) {
  std::vector<float> matrices;
  for (int node : order) {
    const std::vector<float> m = {1,
                                  0,
                                  0,
                                  0,
                                  0,
                                  1,
                                  0,
                                  0,
                                  0,
                                  0,
                                  1,
                                  0,
                                  static_cast<float>(shift.x()),
                                  static_cast<float>(shift.y() - node),
                                  static_cast<float>(shift.z()),
                                  1};
    matrices.insert(matrices.end(), m.begin(), m.end());
  }
  return {
      {"joints", order},
      {"inverseBindMatrices", builder->AddAccessor(gltf_test::Bytes(matrices), gltf_test::kFloat,
                                                   "MAT4", static_cast<int>(order.size()))}};
}

TEST(ReadGltf, ConcatenatesEverySkinnedNodeInNodeOrder) {
  const TestRig tube = Tube();
  const int n = tube.mesh.num_vertices();
  const Eigen::Vector3d eye_offset(2, 0, 0);
  // Expected: the body's vertices, then the eye's (the tube shrunk and moved to x = 2).
  const PrimitiveData eye_data = MovedTubePrimitive(tube, eye_offset, 0.5);
  const auto expect_character = [&](const RigImport& read) {
    ASSERT_EQ(read.file_vertex_to_mesh.size(), static_cast<std::size_t>(2 * n));
    ASSERT_EQ(read.mesh.num_vertices(), 2 * n);
    ASSERT_EQ(read.mesh.num_triangles(), 2 * tube.mesh.num_triangles());
    for (int v = 0; v < n; ++v) {
      const int body = read.file_vertex_to_mesh[static_cast<std::size_t>(v)];
      const int eye = read.file_vertex_to_mesh[static_cast<std::size_t>(n + v)];
      EXPECT_LT((read.mesh.vertices.row(body) - tube.mesh.vertices.row(v)).norm(), 1e-6);
      const Eigen::RowVector3d eye_expected(
          eye_data.positions[3 * v], eye_data.positions[3 * v + 1], eye_data.positions[3 * v + 2]);
      EXPECT_LT((read.mesh.vertices.row(eye) - eye_expected).norm(), 1e-6) << v;
      // Both pieces are rigid on the lower bone below y = 1, on the upper one from there.
      const bool lower = tube.mesh.vertices(v, 1) < 1.0;
      EXPECT_NEAR(BoneWeight(read.skeleton, read.weights, eye, "joint0", "joint1"), lower ? 1 : 0,
                  1e-9);
      EXPECT_NEAR(BoneWeight(read.skeleton, read.weights, body, "joint1", "joint2"), lower ? 0 : 1,
                  1e-9);
    }
    ASSERT_EQ(read.skeleton.num_joints(), 3);
    EXPECT_EQ(read.skeleton.joint(0).name, "joint0");
    ASSERT_EQ(read.skinned_nodes.size(), 2u);
    EXPECT_EQ(read.skinned_nodes[0].name, "mesh");
    EXPECT_EQ(read.skinned_nodes[0].first_file_vertex, 0);
    EXPECT_EQ(read.skinned_nodes[0].num_file_vertices, n);
    EXPECT_EQ(read.skinned_nodes[1].name, "eyes");
    EXPECT_EQ(read.skinned_nodes[1].first_file_vertex, n);
    EXPECT_EQ(read.skinned_nodes[1].num_file_vertices, n);
    ASSERT_GE(read.warnings.size(), 1u);
    EXPECT_NE(read.warnings[0].find("2 skinned mesh nodes, in node order: 0.." +
                                    std::to_string(n - 1) + " node 3 'mesh'; " + std::to_string(n) +
                                    ".." + std::to_string(2 * n - 1)),
              std::string::npos)
        << read.warnings[0];
  };
  const auto add_mesh = [](GltfBuilder* builder, const PrimitiveData& data) {
    builder->doc()["meshes"].push_back(
        {{"primitives", nlohmann::json::array({AddPrimitive(builder, data)})}});
    return static_cast<int>(builder->doc()["meshes"].size()) - 1;
  };
  {  // one skin shared by two nodes, and a mesh node without skin (not part of the skin)
    GltfBuilder builder = ChainRig({{0, 0, 0}, {0, 1, 0}, {0, 2, 0}}, {RigidTubePrimitive(tube)});
    const int eye_mesh = add_mesh(&builder, eye_data);
    const int eyes = builder.AddNode({{"name", "eyes"}, {"mesh", eye_mesh}, {"skin", 0}});
    const int prop_mesh = add_mesh(&builder, MovedTubePrimitive(tube, {5, 0, 0}, 1));
    builder.doc()["nodes"][1]["children"].push_back(
        builder.AddNode({{"name", "prop"}, {"mesh", prop_mesh}}));
    builder.doc()["scenes"][0]["nodes"].push_back(eyes);
    auto read = ReadGltf(builder.ToGlb());
    ASSERT_TRUE(read.ok()) << read.status().ToString();
    expect_character(*read);
    // The prop is an open tube under joint1: a candidate bone surface, left out.
    ASSERT_EQ(read->warnings.size(), 2u);
    EXPECT_NE(read->warnings[1].find("'prop' under joint 'joint1' is not a bone surface: it is not "
                                     "closed"),
              std::string::npos)
        << read->warnings[1];
    EXPECT_TRUE(read->bone_surfaces.empty());
  }
  {  // a second skin over the same joints in another order, its mesh in a shifted bind space
    const Eigen::Vector3d shift(3, 0, 0);
    GltfBuilder builder = ChainRig({{0, 0, 0}, {0, 1, 0}, {0, 2, 0}}, {RigidTubePrimitive(tube)});
    builder.doc()["skins"].push_back(ShiftedSkin(&builder, {2, 1, 0}, shift));
    PrimitiveData shifted = MovedTubePrimitive(tube, eye_offset - shift, 0.5);
    for (std::uint8_t& joint : shifted.joints) joint = static_cast<std::uint8_t>(2 - joint);
    for (std::size_t v = 0; v < shifted.joints.size(); v += 4) {
      shifted.joints[v + 1] = shifted.joints[v + 2] = shifted.joints[v + 3] = 0;
    }
    const int eye_mesh = add_mesh(&builder, shifted);
    const int eyes = builder.AddNode({{"name", "eyes"}, {"mesh", eye_mesh}, {"skin", 1}});
    builder.doc()["scenes"][0]["nodes"].push_back(eyes);
    auto read = ReadGltf(builder.ToGlb());
    ASSERT_TRUE(read.ok()) << read.status().ToString();
    expect_character(*read);
    EXPECT_EQ(read->warnings.size(), 1u);
    // Skins binding the joints in different poses (not one transform apart) are refused.
    builder.doc()["skins"][1] = ShiftedSkin(&builder, {2, 1, 0}, {0, 0.5, 0});
    builder.doc()["skins"][1]["inverseBindMatrices"] =
        ShiftedSkin(&builder, {0, 2, 1}, {0, 0, 0})["inverseBindMatrices"];
    ExpectRefused(builder.ToGlb(), StatusCode::kInvalidArgument,
                  "skinned nodes must share one bind pose");
  }
}

TEST(ReadGltf, WarnsOfAScaleImplausibleInMetres) {
  for (const double scale : {1.0, 100.0, 0.001}) {
    TestRig tube = Tube();
    tube.mesh.vertices *= scale;
    std::vector<Joint> joints = tube.skeleton.joints();
    for (Joint& joint : joints) joint.rest_position *= scale;
    tube.skeleton = *Skeleton::Create(joints, {{0, 1}, {1, 2}});
    auto bytes = WriteGltf(tube.mesh, tube.skeleton, tube.weights, GltfContainer::kGlb);
    ASSERT_TRUE(bytes.ok()) << bytes.status().ToString();
    auto read = ReadGltf(*bytes);
    ASSERT_TRUE(read.ok()) << read.status().ToString();
    if (scale == 1.0) {
      EXPECT_TRUE(read->warnings.empty()) << read->warnings.front();
    } else {
      ASSERT_EQ(read->warnings.size(), 1u) << "scale " << scale;
      EXPECT_NE(read->warnings[0].find("implausible for a limb or a character"), std::string::npos)
          << read->warnings[0];
    }
  }
}

TEST(ReadGltf, ReadsASecondInfluenceSet) {
  // Every vertex: joint 0 in JOINTS_0 with 0.25, joint 1 in JOINTS_1 with 0.75.
  const TestRig tube = Tube();
  PrimitiveData data = RigidTubePrimitive(tube);
  std::vector<std::uint8_t> joints_1;
  std::vector<float> weights_1;
  for (int v = 0; v < data.vertex_count(); ++v) {
    data.joints[4 * v] = 0;
    data.weights[4 * v] = 0.25f;
    joints_1.insert(joints_1.end(), {1, 0, 0, 0});
    weights_1.insert(weights_1.end(), {0.75f, 0, 0, 0});
  }
  GltfBuilder builder = ChainRig({{0, 0, 0}, {0, 1, 0}, {0, 2, 0}}, {data});
  auto& attributes = builder.doc()["meshes"][0]["primitives"][0]["attributes"];
  attributes["JOINTS_1"] = builder.AddAccessor(gltf_test::Bytes(joints_1), gltf_test::kUnsignedByte,
                                               "VEC4", data.vertex_count());
  attributes["WEIGHTS_1"] = builder.AddAccessor(gltf_test::Bytes(weights_1), gltf_test::kFloat,
                                                "VEC4", data.vertex_count());
  auto read = ReadGltf(builder.ToGltf());
  ASSERT_TRUE(read.ok()) << read.status().ToString();
  EXPECT_DOUBLE_EQ(BoneWeight(read->skeleton, read->weights, 3, "joint0", "joint1"), 0.25);
  EXPECT_DOUBLE_EQ(BoneWeight(read->skeleton, read->weights, 3, "joint1", "joint2"), 0.75);
}

TEST(ReadGltf, RefusesExternalFiles) {
  const TestRig tube = Tube();
  auto bytes = WriteGltf(tube.mesh, tube.skeleton, tube.weights, GltfContainer::kGltf);
  ASSERT_TRUE(bytes.ok());
  nlohmann::json doc = nlohmann::json::parse(*bytes);
  nlohmann::json external = doc;
  external["buffers"][0]["uri"] = "../../etc/rig.bin";
  ExpectRefused(external.dump(), StatusCode::kInvalidArgument,
                "buffer 0 refers to the external file '../../etc/rig.bin'");
  nlohmann::json image = doc;
  image["images"] = {{{"uri", "skin_texture.png"}}};
  ExpectRefused(image.dump(), StatusCode::kInvalidArgument,
                "image 0 refers to the external file 'skin_texture.png'");
  nlohmann::json odd_data = doc;
  odd_data["buffers"][0]["uri"] = "data:text/html,hello";
  ExpectRefused(odd_data.dump(), StatusCode::kInvalidArgument, "data URI of an unsupported kind");
  // An embedded image is fine (and never decoded).
  nlohmann::json embedded = doc;
  embedded["images"] = {{{"uri", "data:image/png;base64,iVBORw0KGgo="}}};
  EXPECT_TRUE(ReadGltf(embedded.dump()).ok());
}

TEST(ReadGltf, RefusesTruncatedAndGarbageGlb) {
  const TestRig tube = Tube();
  auto glb = WriteGltf(tube.mesh, tube.skeleton, tube.weights, GltfContainer::kGlb);
  ASSERT_TRUE(glb.ok());
  for (std::size_t keep : {std::size_t{4}, std::size_t{19}, std::size_t{20}, glb->size() / 2,
                           glb->size() - 4, glb->size() - 1}) {
    ExpectRefused(glb->substr(0, keep), StatusCode::kInvalidArgument, ".glb");
  }
  ExpectRefused(std::string("glTF") + std::string(60, '\x7f'), StatusCode::kInvalidArgument,
                ".glb");
  // A BIN chunk that claims 8 bytes more than the file holds (tinygltf 2.7 would read past it).
  std::string overlong = *glb;
  const std::size_t json_length = static_cast<unsigned char>(overlong[12]) |
                                  static_cast<unsigned char>(overlong[13]) << 8 |
                                  static_cast<unsigned char>(overlong[14]) << 16;
  overlong[20 + json_length] = static_cast<char>(overlong[20 + json_length] + 8);
  ExpectRefused(overlong, StatusCode::kInvalidArgument, "BIN chunk");
  ExpectRefused("", StatusCode::kInvalidArgument, "empty");
  ExpectRefused("{\"asset\": {\"version\": \"1.0\"}}", StatusCode::kInvalidArgument, "version");
  ExpectRefused(std::string(100, '[') + std::string(100, ']'), StatusCode::kInvalidArgument,
                "nests deeper");
}

TEST(ReadGltf, RefusesWhatASkinnedMeshCannotBe) {
  const TestRig tube = Tube();
  const auto rig = [&tube] {
    return ChainRig({{0, 0, 0}, {0, 1, 0}, {0, 2, 0}}, {RigidTubePrimitive(tube)});
  };
  {  // no skin
    GltfBuilder builder = rig();
    builder.doc()["nodes"][3].erase("skin");
    ExpectRefused(builder.ToGltf(), StatusCode::kInvalidArgument, "no skin: ");
  }
  {  // lines, not triangles
    GltfBuilder builder = rig();
    builder.doc()["meshes"][0]["primitives"][0]["mode"] = 1;
    ExpectRefused(builder.ToGlb(), StatusCode::kInvalidArgument,
                  "primitive 0 of mesh 0 has mode 1; a skinned mesh must be triangles");
  }
  {  // JOINTS_0 names joint 7 of 3
    PrimitiveData data = RigidTubePrimitive(tube);
    data.joints[4 * 5] = 7;
    GltfBuilder builder = ChainRig({{0, 0, 0}, {0, 1, 0}, {0, 2, 0}}, {data});
    ExpectRefused(builder.ToGltf(), StatusCode::kInvalidArgument,
                  "JOINTS_0 of vertex 5 names joint 7 but the skin has 3 joints");
  }
  {  // no weights
    GltfBuilder builder = rig();
    builder.doc()["meshes"][0]["primitives"][0]["attributes"].erase("WEIGHTS_0");
    ExpectRefused(builder.ToGltf(), StatusCode::kInvalidArgument, "no JOINTS_0 and WEIGHTS_0");
  }
  {  // byte weights that are not normalized
    GltfBuilder builder = rig();
    const int weights = builder.doc()["meshes"][0]["primitives"][0]["attributes"]["WEIGHTS_0"];
    builder.doc()["accessors"][weights]["componentType"] = gltf_test::kUnsignedByte;
    ExpectRefused(builder.ToGltf(), StatusCode::kInvalidArgument, "not normalized");
  }
  {  // positions as bytes
    GltfBuilder builder = rig();
    const int positions = builder.doc()["meshes"][0]["primitives"][0]["attributes"]["POSITION"];
    builder.doc()["accessors"][positions]["componentType"] = gltf_test::kUnsignedShort;
    ExpectRefused(builder.ToGltf(), StatusCode::kInvalidArgument,
                  "has component type UNSIGNED_SHORT; expected FLOAT");
  }
  {  // more elements than the bufferView holds
    GltfBuilder builder = rig();
    const int positions = builder.doc()["meshes"][0]["primitives"][0]["attributes"]["POSITION"];
    builder.doc()["accessors"][positions]["count"] = 1000;
    ExpectRefused(builder.ToGltf(), StatusCode::kInvalidArgument, "overrun bufferView");
  }
  {  // a bufferView beyond its buffer
    GltfBuilder builder = rig();
    builder.doc()["bufferViews"][0]["byteOffset"] = 1u << 30;
    ExpectRefused(builder.ToGltf(), StatusCode::kInvalidArgument, "overruns buffer 0");
  }
  {  // an index out of range
    PrimitiveData data = RigidTubePrimitive(tube);
    data.indices[4] = 999;
    GltfBuilder builder = ChainRig({{0, 0, 0}, {0, 1, 0}, {0, 2, 0}}, {data});
    ExpectRefused(builder.ToGltf(), StatusCode::kInvalidArgument, "index 4 is 999");
  }
  {  // a node hierarchy with a cycle
    GltfBuilder builder = rig();
    builder.doc()["nodes"][2]["children"] = {0};
    ExpectRefused(builder.ToGltf(), StatusCode::kInvalidArgument, "cycle");
  }
  {  // a compressed mesh
    GltfBuilder builder = rig();
    builder.doc()["extensionsRequired"] = {"KHR_draco_mesh_compression"};
    ExpectRefused(builder.ToGltf(), StatusCode::kInvalidArgument, "KHR_draco_mesh_compression");
  }
  {  // the vertex limit
    GltfBuilder builder = rig();
    MeshLimits limits;
    limits.max_vertices = 10;
    auto read = ReadGltf(builder.ToGltf(), limits);
    EXPECT_EQ(read.status().code(), StatusCode::kResourceExhausted) << read.status().ToString();
  }
}

}  // namespace
}  // namespace deform
