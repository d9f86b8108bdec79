#include "core/eval/optimized_centers.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdint>

namespace deform {
namespace {

// One triangle's weights for one pair of bones j < k, both positive.
struct PairEntry {
  std::int64_t pair = 0;  // j * num_bones + k
  int triangle = 0;
  double weight_j = 0;
  double weight_k = 0;
};

// Triangle weights: the mean of its corners' compressed weights, as (bone, weight), bone ascending.
void TriangleWeights(const Triangles& triangles, const BoneWeights& weights, int f,
                     std::vector<std::pair<int, double>>* out) {
  out->clear();
  for (int c = 0; c < 3; ++c) {
    const int i = triangles(f, c);
    for (int p = weights.offsets[i]; p < weights.offsets[i + 1]; ++p) {
      out->emplace_back(weights.bones[p], weights.weights[p] / 3.0);
    }
  }
  std::sort(out->begin(), out->end());
  int kept = 0;
  for (std::size_t e = 0; e < out->size(); ++e) {
    if (kept > 0 && (*out)[kept - 1].first == (*out)[e].first) {
      (*out)[kept - 1].second += (*out)[e].second;
    } else {
      (*out)[kept++] = (*out)[e];
    }
  }
  out->resize(kept);
}

}  // namespace

RotationCenters ComputeRotationCenters(const TriangleMesh& mesh, const BoneWeights& weights,
                                       double sigma) {
  const int n = mesh.num_vertices();
  const std::int64_t num_bones = weights.num_bones;
  // Every triangle under every pair of its bones, grouped by pair.
  std::vector<PairEntry> entries;
  std::vector<double> areas(mesh.num_triangles());
  std::vector<Eigen::Vector3d> centroids(mesh.num_triangles());
  std::vector<std::pair<int, double>> triangle_weights;
  for (int f = 0; f < mesh.num_triangles(); ++f) {
    const Eigen::Vector3d a = mesh.vertices.row(mesh.triangles(f, 0)).transpose();
    const Eigen::Vector3d b = mesh.vertices.row(mesh.triangles(f, 1)).transpose();
    const Eigen::Vector3d c = mesh.vertices.row(mesh.triangles(f, 2)).transpose();
    areas[f] = 0.5 * (b - a).cross(c - a).norm();
    centroids[f] = (a + b + c) / 3.0;
    TriangleWeights(mesh.triangles, weights, f, &triangle_weights);
    for (std::size_t x = 0; x < triangle_weights.size(); ++x) {
      for (std::size_t y = x + 1; y < triangle_weights.size(); ++y) {
        entries.push_back({triangle_weights[x].first * num_bones + triangle_weights[y].first, f,
                           triangle_weights[x].second, triangle_weights[y].second});
      }
    }
  }
  std::sort(entries.begin(), entries.end(), [](const PairEntry& a, const PairEntry& b) {
    return a.pair != b.pair ? a.pair < b.pair : a.triangle < b.triangle;
  });

  RotationCenters result;
  result.centers = Positions::Zero(n, 3);
  result.has_center.assign(n, 0);
  const double inverse_sigma_squared = 1.0 / (sigma * sigma);
  for (int i = 0; i < n; ++i) {
    Eigen::Vector3d weighted_sum = Eigen::Vector3d::Zero();
    double total = 0;
    for (int p = weights.offsets[i]; p < weights.offsets[i + 1]; ++p) {
      for (int r = p + 1; r < weights.offsets[i + 1]; ++r) {
        // The pair's bones in ascending order, with the vertex's weights to match.
        const bool ascending = weights.bones[p] < weights.bones[r];
        const int j = ascending ? weights.bones[p] : weights.bones[r];
        const int k = ascending ? weights.bones[r] : weights.bones[p];
        const double wij = ascending ? weights.weights[p] : weights.weights[r];
        const double wik = ascending ? weights.weights[r] : weights.weights[p];
        const std::int64_t key = j * num_bones + k;
        auto first =
            std::lower_bound(entries.begin(), entries.end(), key,
                             [](const PairEntry& e, std::int64_t v) { return e.pair < v; });
        for (auto e = first; e != entries.end() && e->pair == key; ++e) {
          const double difference = wij * e->weight_k - wik * e->weight_j;
          const double similarity = wij * wik * e->weight_j * e->weight_k *
                                    std::exp(-difference * difference * inverse_sigma_squared);
          const double mass = similarity * areas[e->triangle];
          weighted_sum += mass * centroids[e->triangle];
          total += mass;
        }
      }
    }
    if (total > 0) {
      result.centers.row(i) = (weighted_sum / total).transpose();
      result.has_center[i] = 1;
    } else {
      ++result.num_without_center;
    }
  }
  return result;
}

void OptimizedCentersSkinning(const Positions& rest, const BoneWeights& weights,
                              const RotationCenters& centers,
                              const std::vector<RigidTransform>& bone_transforms,
                              Positions* posed) {
  posed->resize(rest.rows(), 3);
  for (int i = 0; i < rest.rows(); ++i) {
    const Eigen::Vector3d v = rest.row(i).transpose();
    const int begin = weights.offsets[i];
    const int end = weights.offsets[i + 1];
    if (!centers.has_center[i]) {
      Eigen::Vector3d x = Eigen::Vector3d::Zero();
      for (int p = begin; p < end; ++p) {
        x += weights.weights[p] * bone_transforms[weights.bones[p]].Apply(v);
      }
      posed->row(i) = x.transpose();
      continue;
    }
    const Eigen::Vector3d center = centers.centers.row(i).transpose();
    const Eigen::Quaterniond& pivot = bone_transforms[weights.bones[begin]].rotation;
    Eigen::Vector4d blend = Eigen::Vector4d::Zero();
    Eigen::Vector3d skinned_center = Eigen::Vector3d::Zero();
    for (int p = begin; p < end; ++p) {
      const RigidTransform& bone = bone_transforms[weights.bones[p]];
      const double w = weights.weights[p];
      blend += (pivot.dot(bone.rotation) < 0 ? -w : w) * bone.rotation.coeffs();
      skinned_center += w * bone.Apply(center);
    }
    const Eigen::Quaterniond rotation(Eigen::Vector4d(blend.normalized()));
    posed->row(i) = (rotation * v + skinned_center - rotation * center).transpose();
  }
}

}  // namespace deform
