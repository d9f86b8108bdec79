#include "gltf_weld.h"

#include <cmath>
#include <cstdint>
#include <cstring>
#include <unordered_map>

namespace deform::gltf_internal {
namespace {

// Distinct weightings kept per position: more coincident vertices than this (which no real mesh
// has) are not compared further, so crafted input cannot make welding quadratic.
constexpr std::size_t kMaxWeldCandidates = 8;

struct PositionKey {
  std::uint64_t bits[3];
  bool operator==(const PositionKey& other) const {
    return bits[0] == other.bits[0] && bits[1] == other.bits[1] && bits[2] == other.bits[2];
  }
};

struct PositionKeyHash {
  std::size_t operator()(const PositionKey& key) const {
    std::uint64_t h = 1469598103934665603ull;
    for (std::uint64_t b : key.bits) h = (h ^ b) * 1099511628211ull;
    return static_cast<std::size_t>(h ^ (h >> 29));
  }
};

PositionKey KeyOf(const Positions& positions, int v) {
  PositionKey key;
  for (int c = 0; c < 3; ++c) {
    const double value = positions(v, c) + 0.0;  // -0 becomes +0
    std::memcpy(&key.bits[c], &value, sizeof(value));
  }
  return key;
}

bool SameWeights(const SkinWeights& weights, int a, int b) {
  const int na = weights.offsets[a + 1] - weights.offsets[a];
  if (na != weights.offsets[b + 1] - weights.offsets[b]) return false;
  for (int k = 0; k < na; ++k) {
    const int ea = weights.offsets[a] + k;
    const int eb = weights.offsets[b] + k;
    if (weights.bones[ea] != weights.bones[eb] ||
        std::abs(weights.weights[ea] - weights.weights[eb]) > kWeldWeightTolerance) {
      return false;
    }
  }
  return true;
}

// Gives each unused file vertex (-1 in `map`) the mesh vertex of the used one before it in the
// file, or of the first used one for those before every used vertex; lists them.
void FollowUsedVertices(std::vector<int>* map, std::vector<int>* unused) {
  int followed = -1;
  for (const int m : *map) {
    if (m >= 0) {
      followed = m;  // the first used vertex, for the unused ones at the file's start
      break;
    }
  }
  unused->clear();
  for (std::size_t f = 0; f < map->size(); ++f) {
    int& m = (*map)[f];
    if (m >= 0) {
      followed = m;
    } else {
      m = followed;
      unused->push_back(static_cast<int>(f));
    }
  }
}

}  // namespace

WeldedMesh WeldSeams(const Positions& positions, const SkinWeights& weights,
                     const Triangles& triangles) {
  const int num_file = static_cast<int>(positions.rows());
  // First pass: each file vertex's representative (the first file vertex it welds to).
  std::vector<int> representative(static_cast<std::size_t>(num_file));
  std::unordered_map<PositionKey, std::vector<int>, PositionKeyHash> by_position;
  by_position.reserve(static_cast<std::size_t>(num_file));
  for (int v = 0; v < num_file; ++v) {
    std::vector<int>& same_place = by_position[KeyOf(positions, v)];
    int found = v;
    for (int candidate : same_place) {
      if (SameWeights(weights, candidate, v)) {
        found = candidate;
        break;
      }
    }
    if (found == v && same_place.size() < kMaxWeldCandidates) same_place.push_back(v);
    representative[static_cast<std::size_t>(v)] = found;
  }
  // Representatives that some triangle uses, numbered in file order.
  std::vector<char> used(static_cast<std::size_t>(num_file), 0);
  for (Eigen::Index t = 0; t < triangles.rows(); ++t) {
    for (int c = 0; c < 3; ++c) {
      used[static_cast<std::size_t>(representative[static_cast<std::size_t>(triangles(t, c))])] = 1;
    }
  }
  std::vector<int> welded_index(static_cast<std::size_t>(num_file), -1);
  int num_welded = 0;
  for (int v = 0; v < num_file; ++v) {
    if (representative[static_cast<std::size_t>(v)] == v && used[static_cast<std::size_t>(v)]) {
      welded_index[static_cast<std::size_t>(v)] = num_welded++;
    }
  }
  WeldedMesh result;
  result.file_vertex_to_mesh.resize(static_cast<std::size_t>(num_file));
  result.mesh.vertices.resize(num_welded, 3);
  result.weights.num_bones = weights.num_bones;
  for (int v = 0; v < num_file; ++v) {
    const int w =
        welded_index[static_cast<std::size_t>(representative[static_cast<std::size_t>(v)])];
    result.file_vertex_to_mesh[static_cast<std::size_t>(v)] = w;
    if (welded_index[static_cast<std::size_t>(v)] < 0) continue;
    result.mesh.vertices.row(w) = positions.row(v);
    for (int e = weights.offsets[v]; e < weights.offsets[v + 1]; ++e) {
      result.weights.bones.push_back(weights.bones[e]);
      result.weights.weights.push_back(weights.weights[e]);
    }
    result.weights.offsets.push_back(static_cast<int>(result.weights.bones.size()));
  }
  result.mesh.triangles.resize(triangles.rows(), 3);
  for (Eigen::Index t = 0; t < triangles.rows(); ++t) {
    for (int c = 0; c < 3; ++c) {
      result.mesh.triangles(t, c) =
          result.file_vertex_to_mesh[static_cast<std::size_t>(triangles(t, c))];
    }
  }
  FollowUsedVertices(&result.file_vertex_to_mesh, &result.unused_vertices);
  return result;
}

}  // namespace deform::gltf_internal
