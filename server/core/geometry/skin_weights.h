// Per-vertex skinning weights over a skeleton's bones, as rigs carry them: sparse, a few bones per
// vertex. What a user supplies (DMAT, CSV, glTF) before the model turns it into its binding.
#pragma once

#include <vector>

#include "core/base/status.h"

namespace deform {

// Vertex i's entries are [offsets[i], offsets[i + 1]) of `bones` and `weights`. Bone indices refer
// to the skeleton's bones (Skeleton::bone), in its bone order.
struct SkinWeights {
  int num_bones = 0;
  std::vector<int> offsets{0};  // #V + 1, non-decreasing, offsets[0] == 0
  std::vector<int> bones;
  std::vector<double> weights;

  int num_vertices() const { return static_cast<int>(offsets.size()) - 1; }
  // Appends the next vertex's entries (in any order; zero weights are dropped).
  void AddVertex(const std::vector<int>& vertex_bones, const std::vector<double>& vertex_weights);
};

// Checks `weights` against a mesh of `num_vertices` and a skeleton of `num_bones`, and returns
// them cleaned: entries sorted by bone per vertex, repeated bones summed, weights below
// kSkinWeightDropBelow of the vertex's total dropped, rows renormalized to sum to 1.
// INVALID_ARGUMENT naming the first problem: a vertex count or bone count that differs, a bone
// index out of range, a negative or non-finite weight, a vertex whose weights sum to zero (it
// would follow no bone), malformed offsets.
inline constexpr double kSkinWeightDropBelow = 1e-6;
StatusOr<SkinWeights> NormalizeSkinWeights(const SkinWeights& weights, int num_vertices,
                                           int num_bones);

}  // namespace deform
