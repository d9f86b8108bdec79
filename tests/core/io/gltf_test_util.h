// Rigs and glTF files for the glTF import tests, written here (not by the library) so that the
// tests can make the malformed and unusual files that real exporters produce.
//
//   Tube():        an open tube along +Y (rings of vertices from y = 0 to y = 2) on a chain of
//                  three joints at y = 0, 1, 2, blending between the two bones around y = 1.
//   GltfBuilder:   a glTF document assembled from raw accessors: every accessor gets its own
//                  bufferView in one buffer; ToGltf() embeds it as a data URI (the io layer's
//                  Base64Encode, which base64_test.cc checks on its own), ToGlb() as the BIN chunk.
//   SkinAsGltf:    a primitive skinned as glTF skins it (joint matrices, weights), written here
//                  as the reference a pose's linear blend skinning is checked against.
#pragma once

#include <gtest/gtest.h>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "core/geometry/mesh.h"
#include "core/geometry/skeleton.h"
#include "core/geometry/skin_weights.h"
#include "core/io/base64.h"

namespace deform::gltf_test {

inline constexpr int kUnsignedByte = 5121;
inline constexpr int kUnsignedShort = 5123;
inline constexpr int kUnsignedInt = 5125;
inline constexpr int kFloat = 5126;

struct TestRig {
  TriangleMesh mesh;
  Skeleton skeleton;
  SkinWeights weights;
};

// Bone 0's weight at height y; bone 1 has the rest.
inline double LowerBoneWeight(double y) { return std::clamp(1.5 - y, 0.0, 1.0); }

inline TestRig Tube(int sides = 8, int rings = 5) {
  TestRig rig;
  rig.mesh.vertices.resize(sides * rings, 3);
  for (int r = 0; r < rings; ++r) {
    const double y = 2.0 * r / (rings - 1);
    for (int s = 0; s < sides; ++s) {
      const double angle = 2 * M_PI * s / sides;
      rig.mesh.vertices.row(r * sides + s) << 0.3 * std::cos(angle), y, 0.3 * std::sin(angle);
    }
  }
  rig.mesh.triangles.resize(2 * sides * (rings - 1), 3);
  int t = 0;
  for (int r = 0; r + 1 < rings; ++r) {
    for (int s = 0; s < sides; ++s) {
      const int a = r * sides + s, b = r * sides + (s + 1) % sides;
      const int c = a + sides, d = b + sides;
      rig.mesh.triangles.row(t++) << a, c, b;
      rig.mesh.triangles.row(t++) << b, c, d;
    }
  }
  std::vector<Joint> joints = {
      {"hip", {0, 0, 0}, {}}, {"knee", {0, 1, 0}, {}}, {"ankle", {0, 2, 0}, {}}};
  rig.skeleton = *Skeleton::Create(joints, {{0, 1}, {1, 2}});
  rig.weights.num_bones = 2;
  for (int v = 0; v < rig.mesh.num_vertices(); ++v) {
    const double w = LowerBoneWeight(rig.mesh.vertices(v, 1));
    rig.weights.AddVertex({0, 1}, {w, 1 - w});
  }
  return rig;
}

template <typename T>
std::string Bytes(const std::vector<T>& values) {
  return std::string(reinterpret_cast<const char*>(values.data()), values.size() * sizeof(T));
}

class GltfBuilder {
 public:
  GltfBuilder() {
    doc_["asset"] = {{"version", "2.0"}};
    doc_["bufferViews"] = nlohmann::json::array();
    doc_["accessors"] = nlohmann::json::array();
    doc_["nodes"] = nlohmann::json::array();
  }

  // Adds `bytes` as a bufferView (with `byte_stride` when non-zero) and an accessor over it.
  int AddAccessor(const std::string& bytes, int component_type, const std::string& type, int count,
                  bool normalized = false, int byte_stride = 0) {
    while (buffer_.size() % 4 != 0) buffer_.push_back('\0');
    nlohmann::json view = {
        {"buffer", 0}, {"byteOffset", buffer_.size()}, {"byteLength", bytes.size()}};
    if (byte_stride != 0) view["byteStride"] = byte_stride;
    buffer_ += bytes;
    doc_["bufferViews"].push_back(view);
    nlohmann::json accessor = {{"bufferView", doc_["bufferViews"].size() - 1},
                               {"componentType", component_type},
                               {"count", count},
                               {"type", type}};
    if (normalized) accessor["normalized"] = true;
    doc_["accessors"].push_back(accessor);
    return static_cast<int>(doc_["accessors"].size()) - 1;
  }
  int AddNode(nlohmann::json node) {
    doc_["nodes"].push_back(std::move(node));
    return static_cast<int>(doc_["nodes"].size()) - 1;
  }
  nlohmann::json& doc() { return doc_; }

  std::string ToGltf() {
    nlohmann::json doc = Finished();
    doc["buffers"][0]["uri"] = "data:application/octet-stream;base64," + Base64Encode(buffer_);
    return doc.dump();
  }
  std::string ToGlb() {
    std::string json = Finished().dump();
    while (json.size() % 4 != 0) json.push_back(' ');
    std::string binary = buffer_;
    while (binary.size() % 4 != 0) binary.push_back('\0');
    std::string out = "glTF";
    const auto put = [&out](std::uint32_t value) {
      for (int b = 0; b < 4; ++b) out.push_back(static_cast<char>((value >> (8 * b)) & 0xff));
    };
    put(2);
    put(static_cast<std::uint32_t>(28 + json.size() + binary.size()));
    put(static_cast<std::uint32_t>(json.size()));
    put(0x4E4F534A);
    out += json;
    put(static_cast<std::uint32_t>(binary.size()));
    put(0x004E4942);
    return out + binary;
  }

 private:
  nlohmann::json Finished() const {
    nlohmann::json doc = doc_;
    doc["buffers"] = {{{"byteLength", buffer_.size()}}};
    return doc;
  }

  nlohmann::json doc_;
  std::string buffer_;
};

// One skinned primitive's data: positions, triangle corners (empty: not indexed), and per vertex
// up to four (joint, weight) influences.
struct PrimitiveData {
  std::vector<float> positions;  // xyz per vertex
  std::vector<std::uint32_t> indices;
  std::vector<std::uint8_t> joints;  // 4 per vertex
  std::vector<float> weights;        // 4 per vertex
  int vertex_count() const { return static_cast<int>(positions.size() / 3); }
};

// The Tube as one primitive's data with rigid weights (joint 0 below y = 1, joint 1 from there),
// exactly representable as normalized bytes.
inline PrimitiveData RigidTubePrimitive(const TestRig& tube) {
  PrimitiveData data;
  for (int v = 0; v < tube.mesh.num_vertices(); ++v) {
    for (int c = 0; c < 3; ++c)
      data.positions.push_back(static_cast<float>(tube.mesh.vertices(v, c)));
    const bool lower = tube.mesh.vertices(v, 1) < 1.0;
    data.joints.insert(data.joints.end(), {static_cast<std::uint8_t>(lower ? 0 : 1), 0, 0, 0});
    data.weights.insert(data.weights.end(), {1.0f, 0.0f, 0.0f, 0.0f});
  }
  for (Eigen::Index t = 0; t < tube.mesh.triangles.rows(); ++t) {
    for (int c = 0; c < 3; ++c)
      data.indices.push_back(static_cast<std::uint32_t>(tube.mesh.triangles(t, c)));
  }
  return data;
}

// A primitive JSON object for `data`, its accessors added to `builder`.
inline nlohmann::json AddPrimitive(GltfBuilder* builder, const PrimitiveData& data) {
  nlohmann::json attributes;
  attributes["POSITION"] =
      builder->AddAccessor(Bytes(data.positions), kFloat, "VEC3", data.vertex_count());
  attributes["JOINTS_0"] =
      builder->AddAccessor(Bytes(data.joints), kUnsignedByte, "VEC4", data.vertex_count());
  attributes["WEIGHTS_0"] =
      builder->AddAccessor(Bytes(data.weights), kFloat, "VEC4", data.vertex_count());
  nlohmann::json primitive = {{"attributes", attributes}};
  if (!data.indices.empty()) {
    primitive["indices"] = builder->AddAccessor(Bytes(data.indices), kUnsignedInt, "SCALAR",
                                                static_cast<int>(data.indices.size()));
  }
  return primitive;
}

// A builder holding a chain of joint nodes at `positions` (each the child of the one before, by
// translation; no inverse bind matrices) named joint0.., a skin over them, and a mesh node with
// `primitives`.
inline GltfBuilder ChainRig(const std::vector<Eigen::Vector3d>& positions,
                            const std::vector<PrimitiveData>& primitives) {
  GltfBuilder builder;
  for (std::size_t j = 0; j < positions.size(); ++j) {
    const Eigen::Vector3d offset =
        j == 0 ? positions[0] : Eigen::Vector3d(positions[j] - positions[j - 1]);
    nlohmann::json node = {{"name", "joint" + std::to_string(j)},
                           {"translation", {offset.x(), offset.y(), offset.z()}}};
    if (j + 1 < positions.size()) node["children"] = {j + 1};
    builder.AddNode(node);
  }
  std::vector<int> joints(positions.size());
  for (std::size_t j = 0; j < positions.size(); ++j) joints[j] = static_cast<int>(j);
  builder.doc()["skins"] = {{{"joints", joints}}};
  nlohmann::json mesh = {{"primitives", nlohmann::json::array()}};
  for (const PrimitiveData& data : primitives)
    mesh["primitives"].push_back(AddPrimitive(&builder, data));
  builder.doc()["meshes"] = nlohmann::json::array({mesh});
  builder.AddNode({{"name", "mesh"}, {"mesh", 0}, {"skin", 0}});
  builder.doc()["scenes"] = {{{"nodes", {0, positions.size()}}}};
  return builder;
}

// The local matrix of a node with `translation` and `rotation` (glTF's T * R).
inline Eigen::Matrix4d NodeMatrix(const Eigen::Vector3d& translation,
                                  const Eigen::Quaterniond& rotation) {
  Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
  m.block<3, 3>(0, 0) = rotation.toRotationMatrix();
  m.block<3, 1>(0, 3) = translation;
  return m;
}

// `data`'s vertices skinned as glTF does: sum over influences of weight * joint matrix * position
// (weights renormalized), `joint_matrix` indexed by the skin's joint.
inline Positions SkinAsGltf(const PrimitiveData& data,
                            const std::vector<Eigen::Matrix4d>& joint_matrix) {
  const int n = data.vertex_count();
  Positions skinned(n, 3);
  for (int v = 0; v < n; ++v) {
    const Eigen::Vector4d p(data.positions[3 * v], data.positions[3 * v + 1],
                            data.positions[3 * v + 2], 1);
    Eigen::Vector4d sum = Eigen::Vector4d::Zero();
    double total = 0;
    for (int k = 0; k < 4; ++k) {
      const double w = data.weights[4 * v + k];
      sum += w * (joint_matrix[data.joints[4 * v + k]] * p);
      total += w;
    }
    skinned.row(v) = (sum / total).head<3>().transpose();
  }
  return skinned;
}

}  // namespace deform::gltf_test
