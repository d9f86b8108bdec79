#include "gltf_skinned_mesh.h"

#include <algorithm>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "gltf_accessors.h"
#include "mesh_io_internal.h"

namespace deform::gltf_internal {
namespace {

using Normalization = AccessorSpec::IntegerNormalization;

// One primitive's attribute accessor by name, or -1.
int Attribute(const tinygltf::Primitive& primitive, const std::string& name) {
  const auto it = primitive.attributes.find(name);
  return it == primitive.attributes.end() ? -1 : it->second;
}

struct InfluenceSet {
  AccessorValues joints;
  AccessorValues weights;
};

// The primitive's JOINTS_n / WEIGHTS_n pairs, n = 0, 1, ... while present.
StatusOr<std::vector<InfluenceSet>> ReadInfluenceSets(const tinygltf::Model& model,
                                                      const tinygltf::Primitive& primitive,
                                                      const std::string& where, int count) {
  if (Attribute(primitive, "JOINTS_0") < 0 || Attribute(primitive, "WEIGHTS_0") < 0) {
    return Status::InvalidArgument(where +
                                   " has no JOINTS_0 and WEIGHTS_0; every primitive of a skinned "
                                   "mesh needs them");
  }
  std::vector<InfluenceSet> sets;
  for (int set = 0;; ++set) {
    const std::string joints_name = "JOINTS_" + std::to_string(set);
    const std::string weights_name = "WEIGHTS_" + std::to_string(set);
    const int joints_index = Attribute(primitive, joints_name);
    const int weights_index = Attribute(primitive, weights_name);
    if (joints_index < 0 && weights_index < 0) break;
    if (joints_index < 0 || weights_index < 0) {
      return Status::InvalidArgument(where + " has " +
                                     (joints_index < 0 ? weights_name : joints_name) + " without " +
                                     (joints_index < 0 ? joints_name : weights_name));
    }
    InfluenceSet influence;
    DEFORM_ASSIGN_OR_RETURN(influence.joints,
                            ReadAccessor(model, joints_index,
                                         {joints_name + " of " + where,
                                          {TINYGLTF_TYPE_VEC4},
                                          {TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE,
                                           TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT},
                                          Normalization::kNever,
                                          std::numeric_limits<std::uint64_t>::max(),
                                          "elements",
                                          static_cast<std::uint64_t>(count)}));
    DEFORM_ASSIGN_OR_RETURN(
        influence.weights,
        ReadAccessor(model, weights_index,
                     {weights_name + " of " + where,
                      {TINYGLTF_TYPE_VEC4},
                      {TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE,
                       TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT},
                      Normalization::kRequired,
                      std::numeric_limits<std::uint64_t>::max(),
                      "elements",
                      static_cast<std::uint64_t>(count)}));
    sets.push_back(std::move(influence));
  }
  return sets;
}

// Appends each vertex's non-zero influences to `joint_weights`.
Status AppendInfluences(const std::vector<InfluenceSet>& sets, const std::string& where, int count,
                        int num_joints, SkinWeights* joint_weights) {
  std::vector<int> joints;
  std::vector<double> weights;
  for (int v = 0; v < count; ++v) {
    joints.clear();
    weights.clear();
    for (std::size_t s = 0; s < sets.size(); ++s) {
      for (int c = 0; c < 4; ++c) {
        const double joint = sets[s].joints.at(v, c);
        const double weight = sets[s].weights.at(v, c);
        if (joint >= num_joints) {
          return Status::InvalidArgument(
              where + ": JOINTS_" + std::to_string(s) + " of vertex " + std::to_string(v) +
              " names joint " + std::to_string(static_cast<long long>(joint)) +
              " but the skin has " + std::to_string(num_joints) + " joints");
        }
        if (weight < 0) {
          return Status::InvalidArgument(where + ": WEIGHTS_" + std::to_string(s) + " of vertex " +
                                         std::to_string(v) + " is negative");
        }
        joints.push_back(static_cast<int>(joint));
        weights.push_back(weight);
      }
    }
    joint_weights->AddVertex(joints, weights);  // drops the zero weights
  }
  return Status::Ok();
}

// The primitive's triangle corners (indices into its own vertices): from its indices accessor, or
// consecutive vertex triples when it has none.
StatusOr<std::vector<int>> ReadCorners(const tinygltf::Model& model,
                                       const tinygltf::Primitive& primitive,
                                       const std::string& where, int count,
                                       const MeshLimits& limits) {
  std::vector<int> corners;
  if (primitive.indices >= 0) {
    DEFORM_ASSIGN_OR_RETURN(const AccessorValues indices,
                            ReadAccessor(model, primitive.indices,
                                         {"indices of " + where,
                                          {TINYGLTF_TYPE_SCALAR},
                                          {TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE,
                                           TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT,
                                           TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT},
                                          Normalization::kNever,
                                          3 * static_cast<std::uint64_t>(limits.max_triangles),
                                          "indices (3 per triangle)"}));
    corners.reserve(indices.values.size());
    for (std::size_t k = 0; k < indices.values.size(); ++k) {
      if (indices.values[k] >= count) {
        return Status::InvalidArgument(where + ": index " + std::to_string(k) + " is " +
                                       std::to_string(static_cast<long long>(indices.values[k])) +
                                       " but the primitive has " + std::to_string(count) +
                                       " vertices");
      }
      corners.push_back(static_cast<int>(indices.values[k]));
    }
  } else {
    corners.resize(static_cast<std::size_t>(count));
    for (int v = 0; v < count; ++v) corners[static_cast<std::size_t>(v)] = v;
  }
  if (corners.empty() || corners.size() % 3 != 0) {
    return Status::InvalidArgument(where + " has " + std::to_string(corners.size()) +
                                   " triangle corners, not a positive multiple of 3");
  }
  return corners;
}

// One primitive, read whole before anything is appended.
struct PrimitiveData {
  AccessorValues positions;
  std::vector<InfluenceSet> influences;
  std::vector<int> corners;
};

StatusOr<PrimitiveData> ReadPrimitive(const tinygltf::Model& model,
                                      const tinygltf::Primitive& primitive,
                                      const std::string& where, std::uint64_t vertex_room,
                                      const MeshLimits& limits, bool skinned) {
  if (primitive.mode != TINYGLTF_MODE_TRIANGLES) {
    return Status::InvalidArgument(where + " has mode " + std::to_string(primitive.mode) +
                                   (skinned ? "; a skinned mesh" : "; a bone surface") +
                                   " must be triangles (mode 4)");
  }
  if (Attribute(primitive, "POSITION") < 0) {
    return Status::InvalidArgument(where + " has no POSITION");
  }
  PrimitiveData data;
  DEFORM_ASSIGN_OR_RETURN(data.positions,
                          ReadAccessor(model, Attribute(primitive, "POSITION"),
                                       {"POSITION of " + where,
                                        {TINYGLTF_TYPE_VEC3},
                                        {TINYGLTF_COMPONENT_TYPE_FLOAT},
                                        Normalization::kNever,
                                        vertex_room,
                                        "vertices (with the primitives before it)"}));
  if (skinned) {
    DEFORM_ASSIGN_OR_RETURN(data.influences,
                            ReadInfluenceSets(model, primitive, where, data.positions.count));
  }
  DEFORM_ASSIGN_OR_RETURN(data.corners,
                          ReadCorners(model, primitive, where, data.positions.count, limits));
  return data;
}

// Mesh `mesh_index`'s primitives concatenated; with `num_joints` > 0 their influences too.
StatusOr<FileMesh> ReadMeshPrimitives(const tinygltf::Model& model, int mesh_index, int num_joints,
                                      const MeshLimits& limits) {
  const bool skinned = num_joints > 0;
  const tinygltf::Mesh& gltf_mesh = model.meshes[static_cast<std::size_t>(mesh_index)];
  if (gltf_mesh.primitives.empty()) {
    return Status::InvalidArgument("mesh " + std::to_string(mesh_index) + " has no primitives");
  }
  std::vector<PrimitiveData> primitives;
  std::uint64_t num_vertices = 0;
  std::uint64_t num_triangles = 0;
  FileMesh mesh;
  mesh.joint_weights.num_bones = num_joints;
  for (std::size_t p = 0; p < gltf_mesh.primitives.size(); ++p) {
    const std::string where =
        "primitive " + std::to_string(p) + " of mesh " + std::to_string(mesh_index);
    DEFORM_ASSIGN_OR_RETURN(
        PrimitiveData data,
        ReadPrimitive(
            model, gltf_mesh.primitives[p], where,
            limits.max_vertices - std::min<std::uint64_t>(num_vertices, limits.max_vertices),
            limits, skinned));
    DEFORM_RETURN_IF_ERROR(AppendInfluences(data.influences, where, data.positions.count,
                                            num_joints, &mesh.joint_weights));
    data.influences.clear();  // no longer needed: keep memory to one primitive's worth
    num_vertices += static_cast<std::uint64_t>(data.positions.count);
    num_triangles += data.corners.size() / 3;
    if (num_triangles > limits.max_triangles) {
      return mesh_io_internal::TooManyTriangles(
          skinned ? "the glTF's skinned mesh" : "mesh " + std::to_string(mesh_index),
          limits.max_triangles);
    }
    primitives.push_back(std::move(data));
  }
  mesh.positions.resize(static_cast<Eigen::Index>(num_vertices), 3);
  mesh.triangles.resize(static_cast<Eigen::Index>(num_triangles), 3);
  Eigen::Index vertex = 0;
  Eigen::Index corner = 0;
  for (const PrimitiveData& data : primitives) {
    const Eigen::Index first = vertex;
    for (int v = 0; v < data.positions.count; ++v, ++vertex) {
      for (int c = 0; c < 3; ++c) mesh.positions(vertex, c) = data.positions.at(v, c);
    }
    for (int k : data.corners) {
      mesh.triangles(corner / 3, corner % 3) = static_cast<int>(first) + k;
      ++corner;
    }
  }
  return mesh;
}

}  // namespace

StatusOr<FileMesh> ReadSkinnedMesh(const tinygltf::Model& model, int mesh_index, int num_joints,
                                   const MeshLimits& limits) {
  if (num_joints <= 0) return Status::InvalidArgument("a skin without joints");
  return ReadMeshPrimitives(model, mesh_index, num_joints, limits);
}

StatusOr<FileMesh> ReadStaticMesh(const tinygltf::Model& model, int mesh_index,
                                  const MeshLimits& limits) {
  return ReadMeshPrimitives(model, mesh_index, 0, limits);
}

}  // namespace deform::gltf_internal
