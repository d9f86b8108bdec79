#include "gltf_scene.h"

#include <Eigen/Geometry>
#include <cmath>
#include <string>

namespace deform::gltf_internal {
namespace {

StatusOr<Eigen::Matrix4d> LocalTransform(const tinygltf::Node& node, int index) {
  const std::string what = "node " + std::to_string(index);
  Eigen::Matrix4d local = Eigen::Matrix4d::Identity();
  if (!node.matrix.empty()) {
    if (node.matrix.size() != 16) {
      return Status::InvalidArgument(what + "'s matrix has " + std::to_string(node.matrix.size()) +
                                     " numbers; expected 16");
    }
    for (int k = 0; k < 16; ++k) local(k % 4, k / 4) = node.matrix[static_cast<std::size_t>(k)];
  } else {
    if (!node.translation.empty() && node.translation.size() != 3) {
      return Status::InvalidArgument(what + "'s translation does not have 3 numbers");
    }
    if (!node.scale.empty() && node.scale.size() != 3) {
      return Status::InvalidArgument(what + "'s scale does not have 3 numbers");
    }
    if (!node.rotation.empty() && node.rotation.size() != 4) {
      return Status::InvalidArgument(what + "'s rotation does not have 4 numbers");
    }
    Eigen::Affine3d transform = Eigen::Affine3d::Identity();
    if (!node.translation.empty()) {
      transform.translate(
          Eigen::Vector3d(node.translation[0], node.translation[1], node.translation[2]));
    }
    if (!node.rotation.empty()) {
      // glTF stores x, y, z, w; Eigen's constructor takes w, x, y, z.
      Eigen::Quaterniond q(node.rotation[3], node.rotation[0], node.rotation[1], node.rotation[2]);
      const double norm = q.norm();
      if (!std::isfinite(norm) || norm < 1e-12) {
        return Status::InvalidArgument(what + "'s rotation is not a usable quaternion");
      }
      transform.rotate(Eigen::Quaterniond(q.coeffs() / norm));
    }
    if (!node.scale.empty()) {
      transform.scale(Eigen::Vector3d(node.scale[0], node.scale[1], node.scale[2]));
    }
    local = transform.matrix();
  }
  if (!local.allFinite()) {
    return Status::InvalidArgument(what + "'s transform is not finite");
  }
  return local;
}

}  // namespace

StatusOr<SceneNodes> ReadSceneNodes(const tinygltf::Model& model) {
  const int num_nodes = static_cast<int>(model.nodes.size());
  SceneNodes scene;
  scene.parent.assign(model.nodes.size(), -1);
  for (int n = 0; n < num_nodes; ++n) {
    for (int child : model.nodes[static_cast<std::size_t>(n)].children) {
      if (child < 0 || child >= num_nodes) {
        return Status::InvalidArgument("node " + std::to_string(n) + " has child " +
                                       std::to_string(child) + ", which does not exist");
      }
      if (scene.parent[static_cast<std::size_t>(child)] != -1 || child == n) {
        return Status::InvalidArgument("node " + std::to_string(child) +
                                       " has two parents (or is its own child); glTF nodes form "
                                       "a forest");
      }
      scene.parent[static_cast<std::size_t>(child)] = n;
    }
  }
  std::vector<Eigen::Matrix4d> local;
  local.reserve(model.nodes.size());
  for (int n = 0; n < num_nodes; ++n) {
    DEFORM_ASSIGN_OR_RETURN(Eigen::Matrix4d transform,
                            LocalTransform(model.nodes[static_cast<std::size_t>(n)], n));
    local.push_back(transform);
  }
  // World transforms top-down; a node still unresolved after walking up num_nodes steps lies on a
  // cycle.
  scene.world.assign(model.nodes.size(), Eigen::Matrix4d::Identity());
  std::vector<char> done(model.nodes.size(), 0);
  std::vector<int> chain;
  for (int n = 0; n < num_nodes; ++n) {
    chain.clear();
    int at = n;
    while (at != -1 && !done[static_cast<std::size_t>(at)]) {
      chain.push_back(at);
      if (static_cast<int>(chain.size()) > num_nodes) {
        return Status::InvalidArgument("the glTF node hierarchy has a cycle through node " +
                                       std::to_string(n));
      }
      at = scene.parent[static_cast<std::size_t>(at)];
    }
    for (auto it = chain.rbegin(); it != chain.rend(); ++it) {
      const int parent = scene.parent[static_cast<std::size_t>(*it)];
      scene.world[static_cast<std::size_t>(*it)] =
          parent == -1 ? local[static_cast<std::size_t>(*it)]
                       : Eigen::Matrix4d(scene.world[static_cast<std::size_t>(parent)] *
                                         local[static_cast<std::size_t>(*it)]);
      done[static_cast<std::size_t>(*it)] = 1;
      scene.parents_first.push_back(*it);
    }
  }
  return scene;
}

}  // namespace deform::gltf_internal
