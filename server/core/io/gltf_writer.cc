// The glTF writer composes the JSON with nlohmann directly (rather than through tinygltf), so that
// the reader's tests check tinygltf's parsing against an independent writer.
#include "core/io/gltf_writer.h"

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "core/io/base64.h"
#include "internal/mesh_io_internal.h"

namespace deform {
namespace {

constexpr int kFloat = 5126;
constexpr int kUnsignedByte = 5121;
constexpr int kUnsignedShort = 5123;
constexpr int kUnsignedInt = 5125;

// One buffer built section by section; each section becomes a bufferView and an accessor.
class BufferBuilder {
 public:
  explicit BufferBuilder(nlohmann::json* doc) : doc_(doc) {
    (*doc_)["bufferViews"] = nlohmann::json::array();
    (*doc_)["accessors"] = nlohmann::json::array();
  }

  template <typename T>
  int Add(const std::vector<T>& values, int component_type, const char* type, int count,
          nlohmann::json extra = nlohmann::json::object()) {
    while (bytes_.size() % 4 != 0) bytes_.push_back('\0');
    const std::size_t offset = bytes_.size();
    bytes_.append(reinterpret_cast<const char*>(values.data()), values.size() * sizeof(T));
    (*doc_)["bufferViews"].push_back(
        {{"buffer", 0}, {"byteOffset", offset}, {"byteLength", values.size() * sizeof(T)}});
    nlohmann::json accessor = {{"bufferView", (*doc_)["bufferViews"].size() - 1},
                               {"componentType", component_type},
                               {"count", count},
                               {"type", type}};
    accessor.update(extra);
    (*doc_)["accessors"].push_back(accessor);
    return static_cast<int>((*doc_)["accessors"].size()) - 1;
  }

  std::string& bytes() { return bytes_; }

 private:
  nlohmann::json* doc_;
  std::string bytes_;
};

// Per vertex, (joint, weight) pairs: each bone's weight on its head joint, summed.
std::vector<std::vector<std::pair<int, float>>> JointInfluences(const Skeleton& skeleton,
                                                                const SkinWeights& weights) {
  std::vector<std::vector<std::pair<int, float>>> influences(
      static_cast<std::size_t>(weights.num_vertices()));
  for (int v = 0; v < weights.num_vertices(); ++v) {
    std::map<int, double> by_joint;
    for (int e = weights.offsets[v]; e < weights.offsets[v + 1]; ++e) {
      by_joint[skeleton.bone(weights.bones[e]).head_joint] += weights.weights[e];
    }
    for (const auto& [joint, weight] : by_joint) {
      influences[static_cast<std::size_t>(v)].emplace_back(joint, static_cast<float>(weight));
    }
  }
  return influences;
}

template <typename JointIndex>
void AddInfluenceSets(const std::vector<std::vector<std::pair<int, float>>>& influences, int sets,
                      int joint_component, BufferBuilder* buffer, nlohmann::json* attributes) {
  const int count = static_cast<int>(influences.size());
  for (int set = 0; set < sets; ++set) {
    std::vector<JointIndex> joints(static_cast<std::size_t>(count) * 4, 0);
    std::vector<float> weights(static_cast<std::size_t>(count) * 4, 0.0f);
    for (std::size_t v = 0; v < influences.size(); ++v) {
      for (int c = 0; c < 4; ++c) {
        const std::size_t k = static_cast<std::size_t>(set * 4 + c);
        if (k >= influences[v].size()) break;
        joints[v * 4 + static_cast<std::size_t>(c)] =
            static_cast<JointIndex>(influences[v][k].first);
        weights[v * 4 + static_cast<std::size_t>(c)] = influences[v][k].second;
      }
    }
    (*attributes)["JOINTS_" + std::to_string(set)] =
        buffer->Add(joints, joint_component, "VEC4", count);
    (*attributes)["WEIGHTS_" + std::to_string(set)] = buffer->Add(weights, kFloat, "VEC4", count);
  }
}

std::string GlbBytes(const std::string& json_text, std::string binary) {
  std::string json = json_text;
  while (json.size() % 4 != 0) json.push_back(' ');
  while (binary.size() % 4 != 0) binary.push_back('\0');
  std::string out;
  const auto put_u32 = [&out](std::uint32_t value) {
    for (int b = 0; b < 4; ++b) out.push_back(static_cast<char>((value >> (8 * b)) & 0xff));
  };
  out.append("glTF");
  put_u32(2);
  put_u32(static_cast<std::uint32_t>(12 + 8 + json.size() + 8 + binary.size()));
  put_u32(static_cast<std::uint32_t>(json.size()));
  put_u32(0x4E4F534A);
  out += json;
  put_u32(static_cast<std::uint32_t>(binary.size()));
  put_u32(0x004E4942);
  out += binary;
  return out;
}

// Adds surface `surface` as a mesh (positions, indices) and a node under its bone's head joint
// node, placed in that joint's frame (a translation by the joint's rest position).
void AddBoneSurface(const BoneSurface& surface, const Skeleton& skeleton, BufferBuilder* buffer,
                    nlohmann::json* doc, std::vector<std::vector<int>>* children) {
  const int joint = skeleton.bone(surface.bone).head_joint;
  const Eigen::Vector3d origin = skeleton.joint(joint).rest_position;
  std::vector<float> positions;
  for (int v = 0; v < surface.mesh.num_vertices(); ++v) {
    for (int c = 0; c < 3; ++c) {
      positions.push_back(static_cast<float>(surface.mesh.vertices(v, c) - origin[c]));
    }
  }
  std::vector<std::uint32_t> indices;
  for (Eigen::Index t = 0; t < surface.mesh.triangles.rows(); ++t) {
    for (int c = 0; c < 3; ++c) {
      indices.push_back(static_cast<std::uint32_t>(surface.mesh.triangles(t, c)));
    }
  }
  nlohmann::json attributes;
  attributes["POSITION"] = buffer->Add(positions, kFloat, "VEC3", surface.mesh.num_vertices());
  const int index_accessor =
      buffer->Add(indices, kUnsignedInt, "SCALAR", static_cast<int>(indices.size()));
  (*doc)["meshes"].push_back(
      {{"primitives", {{{"attributes", attributes}, {"indices", index_accessor}, {"mode", 4}}}}});
  (*doc)["nodes"].push_back(
      {{"name", surface.name}, {"mesh", static_cast<int>((*doc)["meshes"].size()) - 1}});
  (*children)[static_cast<std::size_t>(joint)].push_back(static_cast<int>((*doc)["nodes"].size()) -
                                                         1);
}

}  // namespace

StatusOr<std::string> WriteGltf(const TriangleMesh& mesh, const Skeleton& skeleton,
                                const SkinWeights& weights, GltfContainer container,
                                const std::vector<BoneSurface>& bone_surfaces) {
  DEFORM_RETURN_IF_ERROR(
      ValidateBoneSurfaces(bone_surfaces, skeleton).WithContext("cannot write glTF bone surfaces"));
  DEFORM_ASSIGN_OR_RETURN(const SkinWeights normalized,
                          NormalizeSkinWeights(weights, mesh.num_vertices(), skeleton.num_bones()));
  if (skeleton.num_joints() > 65536) {
    return Status::ResourceExhausted(
        "glTF joints are indexed by unsigned shorts: " + std::to_string(skeleton.num_joints()) +
        " joints are too many");
  }
  for (Eigen::Index t = 0; t < mesh.triangles.rows(); ++t) {
    for (int c = 0; c < 3; ++c) {
      if (mesh.triangles(t, c) < 0 || mesh.triangles(t, c) >= mesh.num_vertices()) {
        return Status::InvalidArgument("cannot write glTF: triangle " + std::to_string(t) +
                                       " has an index out of range");
      }
    }
  }
  nlohmann::json doc;
  doc["asset"] = {{"version", "2.0"}, {"generator", "deformd"}};
  BufferBuilder buffer(&doc);

  // Joints: nodes 0..J-1; the mesh node is node J.
  const int num_joints = skeleton.num_joints();
  doc["nodes"] = nlohmann::json::array();
  std::vector<std::vector<int>> children(static_cast<std::size_t>(num_joints));
  std::vector<int> roots;
  for (int j = 0; j < num_joints; ++j) {
    const int incoming = skeleton.IncomingBone(j);
    const int parent = incoming < 0 ? -1 : skeleton.bone(incoming).head_joint;
    const Eigen::Vector3d offset =
        skeleton.joint(j).rest_position -
        (parent < 0 ? Eigen::Vector3d::Zero() : skeleton.joint(parent).rest_position);
    (parent < 0 ? roots : children[static_cast<std::size_t>(parent)]).push_back(j);
    doc["nodes"].push_back(
        {{"name", skeleton.joint(j).name}, {"translation", {offset.x(), offset.y(), offset.z()}}});
  }
  std::vector<float> inverse_binds;
  for (int j = 0; j < num_joints; ++j) {
    const Eigen::Vector3d p = skeleton.joint(j).rest_position;
    const float column_major[16] = {1,
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
                                    static_cast<float>(-p.x()),
                                    static_cast<float>(-p.y()),
                                    static_cast<float>(-p.z()),
                                    1};
    inverse_binds.insert(inverse_binds.end(), column_major, column_major + 16);
  }
  std::vector<int> joint_nodes(static_cast<std::size_t>(num_joints));
  for (int j = 0; j < num_joints; ++j) joint_nodes[static_cast<std::size_t>(j)] = j;
  const int inverse_bind_accessor = buffer.Add(inverse_binds, kFloat, "MAT4", num_joints);
  doc["skins"] = {{{"joints", joint_nodes}, {"inverseBindMatrices", inverse_bind_accessor}}};

  // The mesh.
  std::vector<float> positions;
  positions.reserve(static_cast<std::size_t>(mesh.num_vertices()) * 3);
  std::vector<double> low(3, 0), high(3, 0);
  for (int v = 0; v < mesh.num_vertices(); ++v) {
    for (int c = 0; c < 3; ++c) {
      const float value = static_cast<float>(mesh.vertices(v, c));
      positions.push_back(value);
      low[static_cast<std::size_t>(c)] =
          v == 0 ? value : std::min<double>(low[static_cast<std::size_t>(c)], value);
      high[static_cast<std::size_t>(c)] =
          v == 0 ? value : std::max<double>(high[static_cast<std::size_t>(c)], value);
    }
  }
  nlohmann::json attributes;
  attributes["POSITION"] =
      buffer.Add(positions, kFloat, "VEC3", mesh.num_vertices(), {{"min", low}, {"max", high}});
  const auto influences = JointInfluences(skeleton, normalized);
  std::size_t most = 1;
  for (const auto& vertex : influences) most = std::max(most, vertex.size());
  const int sets = static_cast<int>((most + 3) / 4);
  if (num_joints <= 256) {
    AddInfluenceSets<std::uint8_t>(influences, sets, kUnsignedByte, &buffer, &attributes);
  } else {
    AddInfluenceSets<std::uint16_t>(influences, sets, kUnsignedShort, &buffer, &attributes);
  }
  std::vector<std::uint32_t> indices;
  indices.reserve(static_cast<std::size_t>(mesh.num_triangles()) * 3);
  for (Eigen::Index t = 0; t < mesh.triangles.rows(); ++t) {
    for (int c = 0; c < 3; ++c) indices.push_back(static_cast<std::uint32_t>(mesh.triangles(t, c)));
  }
  const int index_accessor =
      buffer.Add(indices, kUnsignedInt, "SCALAR", static_cast<int>(indices.size()));
  doc["meshes"] = {
      {{"primitives", {{{"attributes", attributes}, {"indices", index_accessor}, {"mode", 4}}}}}};
  doc["nodes"].push_back({{"name", "mesh"}, {"mesh", 0}, {"skin", 0}});
  roots.push_back(num_joints);
  for (const BoneSurface& surface : bone_surfaces) {
    AddBoneSurface(surface, skeleton, &buffer, &doc, &children);
  }
  for (int j = 0; j < num_joints; ++j) {
    if (!children[static_cast<std::size_t>(j)].empty()) {
      doc["nodes"][static_cast<std::size_t>(j)]["children"] = children[static_cast<std::size_t>(j)];
    }
  }
  doc["scenes"] = {{{"nodes", roots}}};
  doc["scene"] = 0;

  std::string& binary = buffer.bytes();
  while (binary.size() % 4 != 0) binary.push_back('\0');
  doc["buffers"] = {{{"byteLength", binary.size()}}};
  if (container == GltfContainer::kGltf) {
    doc["buffers"][0]["uri"] = "data:application/octet-stream;base64," + Base64Encode(binary);
    return doc.dump(1);
  }
  return GlbBytes(doc.dump(), binary);
}

Status WriteGltfFile(const std::string& path, const TriangleMesh& mesh, const Skeleton& skeleton,
                     const SkinWeights& weights, const std::vector<BoneSurface>& bone_surfaces) {
  const std::string extension = path.substr(std::min(path.size(), path.rfind('.')));
  GltfContainer container;
  if (mesh_io_internal::EqualsIgnoreCase(extension, ".gltf")) {
    container = GltfContainer::kGltf;
  } else if (mesh_io_internal::EqualsIgnoreCase(extension, ".glb")) {
    container = GltfContainer::kGlb;
  } else {
    return Status::InvalidArgument("cannot write " + path + ": expected a .gltf or .glb name");
  }
  DEFORM_ASSIGN_OR_RETURN(const std::string bytes,
                          WriteGltf(mesh, skeleton, weights, container, bone_surfaces));
  std::ofstream out(path, std::ios::binary);
  if (!out) return Status::NotFound("cannot write " + path);
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  if (!out) return Status::Internal("writing " + path + " failed");
  return Status::Ok();
}

}  // namespace deform
