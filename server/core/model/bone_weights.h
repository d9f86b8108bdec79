// Harmonic bone weights (the harmonic guidance field of METHOD.md).
#pragma once

#include <Eigen/Core>
#include <vector>

#include "core/base/status.h"
#include "core/geometry/mesh_topology.h"
#include "core/geometry/skin_weights.h"

namespace deform {

// Per-vertex bone weights h_ik: non-negative, summing to 1 over k for every vertex.
struct BoneWeights {
  int num_bones = 0;
  Eigen::MatrixXd dense;  // #V by K, the harmonic field as solved (in [0, 1], rows sum to 1)
  // Compressed per vertex for blending: weights below kDropBelow are dropped and the rest
  // renormalized. Vertex i's entries are [offsets[i], offsets[i + 1]), largest weight first.
  std::vector<int> offsets;
  std::vector<int> bones;
  std::vector<double> weights;
  static constexpr double kDropBelow = 1e-4;

  int num_vertices() const { return static_cast<int>(offsets.size()) - 1; }
};

// Solves the discrete Laplace equation L h_k = 0 (uniform graph weights, so the maximum principle
// holds and h stays in [0, 1]) with Dirichlet conditions h_k = 1, h_j = 0 (j != k) at every vertex
// whose fixed_bone[i] = k >= 0; vertices with fixed_bone[i] = -1 are free. INVALID_ARGUMENT when a
// connected component has free vertices but no fixed one (its weights would be undetermined).
StatusOr<BoneWeights> HarmonicBoneWeights(const VertexAdjacency& adjacency,
                                          const std::vector<int>& fixed_bone, int num_bones);

// The same with each bone's field kept to the free vertices that may use it: h_k is harmonic on
// the free vertices whose `allowed_bones[i]` lists k, 1 on k's fixed vertices and 0 everywhere
// else, so it falls to 0 where k's joints' regions end instead of spreading across the body. Where
// a free vertex's weights sum to less than 1 (near a region's edge, where every field falls) the
// rest goes to its first allowed bone, its own, so the field stays continuous with the
// neighbouring region's; a sum above 1 is scaled down. `allowed_bones` has one list per vertex
// (the fixed vertices' are ignored); bones in [0, num_bones).
StatusOr<BoneWeights> HarmonicBoneWeights(const VertexAdjacency& adjacency,
                                          const std::vector<int>& fixed_bone, int num_bones,
                                          const std::vector<std::vector<int>>& allowed_bones);

// INVALID_ARGUMENT naming a connected component of the mesh with no vertex in a rigid zone
// (`fixed_bone[i]` >= 0): nothing could anchor it to the skeleton.
Status CheckEveryComponentAnchored(const VertexAdjacency& adjacency,
                                   const std::vector<int>& fixed_bone);

// The rotation field of given skinning weights (normalized for this mesh: NormalizeSkinWeights),
// in the same form as the harmonic field.
BoneWeights BoneWeightsFromSkinWeights(const SkinWeights& weights);

}  // namespace deform
