#include "core/geometry/skin_weights.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <utility>

namespace deform {

void SkinWeights::AddVertex(const std::vector<int>& vertex_bones,
                            const std::vector<double>& vertex_weights) {
  for (std::size_t e = 0; e < vertex_bones.size() && e < vertex_weights.size(); ++e) {
    if (vertex_weights[e] == 0) continue;
    bones.push_back(vertex_bones[e]);
    weights.push_back(vertex_weights[e]);
  }
  offsets.push_back(static_cast<int>(bones.size()));
}

namespace {

Status CheckShape(const SkinWeights& weights, int num_vertices, int num_bones) {
  if (weights.num_vertices() != num_vertices) {
    return Status::InvalidArgument("skinning weights cover " +
                                   std::to_string(weights.num_vertices()) +
                                   " vertices; the mesh has " + std::to_string(num_vertices));
  }
  if (weights.num_bones != num_bones) {
    return Status::InvalidArgument("skinning weights have " + std::to_string(weights.num_bones) +
                                   " bones; the skeleton has " + std::to_string(num_bones));
  }
  if (weights.offsets.empty() || weights.offsets.front() != 0 ||
      weights.offsets.back() != static_cast<int>(weights.bones.size()) ||
      weights.bones.size() != weights.weights.size() ||
      !std::is_sorted(weights.offsets.begin(), weights.offsets.end())) {
    return Status::InvalidArgument("skinning weights: malformed per-vertex offsets");
  }
  return Status::Ok();
}

// Vertex i's entries, sorted by bone with repeats summed; INVALID_ARGUMENT for a bad entry.
Status CollectVertex(const SkinWeights& weights, int i, int num_bones,
                     std::vector<std::pair<int, double>>* entries) {
  entries->clear();
  for (int e = weights.offsets[i]; e < weights.offsets[i + 1]; ++e) {
    const int bone = weights.bones[e];
    const double w = weights.weights[e];
    const std::string where =
        "skinning weight of vertex " + std::to_string(i) + " on bone " + std::to_string(bone);
    if (bone < 0 || bone >= num_bones) {
      return Status::InvalidArgument(where + ": no such bone (the skeleton has " +
                                     std::to_string(num_bones) + ")");
    }
    if (!std::isfinite(w) || w < 0) {
      return Status::InvalidArgument(where + " is " + std::to_string(w) +
                                     " (weights must be finite and non-negative)");
    }
    entries->emplace_back(bone, w);
  }
  std::sort(entries->begin(), entries->end());
  std::size_t kept = 0;
  for (std::size_t e = 0; e < entries->size(); ++e) {
    if (kept > 0 && (*entries)[kept - 1].first == (*entries)[e].first) {
      (*entries)[kept - 1].second += (*entries)[e].second;
    } else {
      (*entries)[kept++] = (*entries)[e];
    }
  }
  entries->resize(kept);
  return Status::Ok();
}

}  // namespace

StatusOr<SkinWeights> NormalizeSkinWeights(const SkinWeights& weights, int num_vertices,
                                           int num_bones) {
  DEFORM_RETURN_IF_ERROR(CheckShape(weights, num_vertices, num_bones));
  SkinWeights result;
  result.num_bones = num_bones;
  result.offsets.reserve(weights.offsets.size());
  result.bones.reserve(weights.bones.size());
  result.weights.reserve(weights.weights.size());
  std::vector<std::pair<int, double>> entries;
  for (int i = 0; i < num_vertices; ++i) {
    DEFORM_RETURN_IF_ERROR(CollectVertex(weights, i, num_bones, &entries));
    double total = 0;
    for (const auto& entry : entries) total += entry.second;
    if (!(total > 0) || !std::isfinite(total)) {
      return Status::InvalidArgument("skinning weights of vertex " + std::to_string(i) +
                                     " sum to " + std::to_string(total) +
                                     " (every vertex must follow at least one bone)");
    }
    double kept_total = 0;
    for (const auto& entry : entries) {
      if (entry.second >= kSkinWeightDropBelow * total) kept_total += entry.second;
    }
    for (const auto& [bone, w] : entries) {
      if (w < kSkinWeightDropBelow * total) continue;
      result.bones.push_back(bone);
      result.weights.push_back(w / kept_total);
    }
    result.offsets.push_back(static_cast<int>(result.bones.size()));
  }
  return result;
}

}  // namespace deform
