#include "core/model/bone_weights.h"

#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>
#include <algorithm>
#include <numeric>
#include <string>

namespace deform {
namespace {

Status SolveFreeVertices(const VertexAdjacency& adjacency, const std::vector<int>& fixed_bone,
                         const std::vector<int>& free_index, int num_free, Eigen::MatrixXd* dense) {
  const int n = static_cast<int>(fixed_bone.size());
  const int num_bones = static_cast<int>(dense->cols());
  std::vector<Eigen::Triplet<double>> triplets;
  Eigen::MatrixXd rhs = Eigen::MatrixXd::Zero(num_free, num_bones);
  for (int i = 0; i < n; ++i) {
    const int fi = free_index[i];
    if (fi < 0) continue;
    triplets.emplace_back(fi, fi, adjacency.degree(i));
    for (int p = adjacency.offsets[i]; p < adjacency.offsets[i + 1]; ++p) {
      const int u = adjacency.neighbors[p];
      if (free_index[u] >= 0) {
        triplets.emplace_back(fi, free_index[u], -1.0);
      } else {
        rhs(fi, fixed_bone[u]) += 1.0;
      }
    }
  }
  Eigen::SparseMatrix<double> laplacian(num_free, num_free);
  laplacian.setFromTriplets(triplets.begin(), triplets.end());
  Eigen::SimplicialLLT<Eigen::SparseMatrix<double>, Eigen::Lower, Eigen::AMDOrdering<int>> llt(
      laplacian);
  if (llt.info() != Eigen::Success) {
    return Status::Internal("harmonic weight system could not be factorized");
  }
  const Eigen::MatrixXd solution = llt.solve(rhs);
  for (int i = 0; i < n; ++i) {
    if (free_index[i] >= 0) dense->row(i) = solution.row(free_index[i]);
  }
  // Round-off can leave tiny negatives; the exact solution lies in [0, 1].
  *dense = dense->cwiseMax(0.0).cwiseMin(1.0);
  return Status::Ok();
}

// Bone `bone`'s field on the free vertices allowed to use it (local index `local`, numbered
// 0..count - 1): harmonic there, 1 on the bone's fixed vertices, 0 on every other vertex.
Status SolveOneBone(const VertexAdjacency& adjacency, const std::vector<int>& fixed_bone,
                    const std::vector<int>& local, int count, int bone, Eigen::MatrixXd* dense) {
  const int n = static_cast<int>(fixed_bone.size());
  std::vector<Eigen::Triplet<double>> triplets;
  Eigen::VectorXd rhs = Eigen::VectorXd::Zero(count);
  for (int i = 0; i < n; ++i) {
    const int li = local[i];
    if (li < 0) continue;
    triplets.emplace_back(li, li, adjacency.degree(i));
    for (int p = adjacency.offsets[i]; p < adjacency.offsets[i + 1]; ++p) {
      const int u = adjacency.neighbors[p];
      if (local[u] >= 0) {
        triplets.emplace_back(li, local[u], -1.0);
      } else if (fixed_bone[u] == bone) {
        rhs[li] += 1.0;
      }
    }
  }
  Eigen::SparseMatrix<double> laplacian(count, count);
  laplacian.setFromTriplets(triplets.begin(), triplets.end());
  Eigen::SimplicialLLT<Eigen::SparseMatrix<double>, Eigen::Lower, Eigen::AMDOrdering<int>> llt(
      laplacian);
  if (llt.info() != Eigen::Success) {
    return Status::Internal("harmonic weight system of bone " + std::to_string(bone) +
                            " could not be factorized");
  }
  const Eigen::VectorXd solution = llt.solve(rhs);
  for (int i = 0; i < n; ++i) {
    if (local[i] >= 0) (*dense)(i, bone) = std::clamp(solution[local[i]], 0.0, 1.0);
  }
  return Status::Ok();
}

// The compressed per-vertex lists of `weights` from its dense field: weights below kDropBelow
// dropped, the rest renormalized, largest first.
void CompressWeights(BoneWeights* weights) {
  const int n = static_cast<int>(weights->dense.rows());
  weights->offsets.assign(n + 1, 0);
  std::vector<std::pair<double, int>> entries;
  for (int i = 0; i < n; ++i) {
    entries.clear();
    for (int k = 0; k < weights->num_bones; ++k) {
      const double h = weights->dense(i, k);
      if (h >= BoneWeights::kDropBelow) entries.emplace_back(h, k);
    }
    std::sort(entries.begin(), entries.end(), std::greater<>());
    double sum = 0;
    for (const auto& e : entries) sum += e.first;
    for (const auto& e : entries) {
      weights->bones.push_back(e.second);
      weights->weights.push_back(e.first / sum);
    }
    weights->offsets[i + 1] = static_cast<int>(weights->bones.size());
  }
}

}  // namespace

Status CheckEveryComponentAnchored(const VertexAdjacency& adjacency,
                                   const std::vector<int>& fixed_bone) {
  std::vector<int> component;
  const int count = ConnectedComponents(adjacency, &component);
  std::vector<int> first_vertex(count, -1), size(count, 0);
  std::vector<char> has_fixed(count, 0);
  for (int i = 0; i < static_cast<int>(component.size()); ++i) {
    const int c = component[i];
    if (first_vertex[c] < 0) first_vertex[c] = i;
    ++size[c];
    if (fixed_bone[i] >= 0) has_fixed[c] = 1;
  }
  for (int c = 0; c < count; ++c) {
    if (!has_fixed[c]) {
      return Status::InvalidArgument(
          "connected component containing vertex " + std::to_string(first_vertex[c]) + " (" +
          std::to_string(size[c]) +
          " vertices) has no vertex in any bone's rigid zone, so it cannot be anchored to the "
          "skeleton");
    }
  }
  return Status::Ok();
}

// The harmonic field on the free vertices (free_index[i] >= 0, numbered 0..num_free - 1): the
// graph Laplacian restricted to them, L_ff h_f = -L_fb h_b = the sum of fixed neighbours' values.
// Writes their rows of `dense` (the fixed rows are already set).
StatusOr<BoneWeights> HarmonicBoneWeights(const VertexAdjacency& adjacency,
                                          const std::vector<int>& fixed_bone, int num_bones) {
  const int n = static_cast<int>(fixed_bone.size());
  DEFORM_RETURN_IF_ERROR(CheckEveryComponentAnchored(adjacency, fixed_bone));
  BoneWeights result;
  result.num_bones = num_bones;
  result.dense = Eigen::MatrixXd::Zero(n, num_bones);
  std::vector<int> free_index(n, -1);
  int num_free = 0;
  for (int i = 0; i < n; ++i) {
    if (fixed_bone[i] < 0) {
      free_index[i] = num_free++;
    } else {
      result.dense(i, fixed_bone[i]) = 1.0;
    }
  }
  if (num_free > 0) {
    DEFORM_RETURN_IF_ERROR(
        SolveFreeVertices(adjacency, fixed_bone, free_index, num_free, &result.dense));
  }
  CompressWeights(&result);
  return result;
}

StatusOr<BoneWeights> HarmonicBoneWeights(const VertexAdjacency& adjacency,
                                          const std::vector<int>& fixed_bone, int num_bones,
                                          const std::vector<std::vector<int>>& allowed_bones) {
  const int n = static_cast<int>(fixed_bone.size());
  DEFORM_RETURN_IF_ERROR(CheckEveryComponentAnchored(adjacency, fixed_bone));
  BoneWeights result;
  result.num_bones = num_bones;
  result.dense = Eigen::MatrixXd::Zero(n, num_bones);
  std::vector<std::vector<int>> free_vertices_of_bone(num_bones);
  for (int i = 0; i < n; ++i) {
    if (fixed_bone[i] >= 0) {
      result.dense(i, fixed_bone[i]) = 1.0;
      continue;
    }
    for (int k : allowed_bones[i]) free_vertices_of_bone[k].push_back(i);
  }
  std::vector<int> local(n, -1);
  for (int k = 0; k < num_bones; ++k) {
    const auto& vertices = free_vertices_of_bone[k];
    if (vertices.empty()) continue;
    for (int v = 0; v < static_cast<int>(vertices.size()); ++v) local[vertices[v]] = v;
    DEFORM_RETURN_IF_ERROR(SolveOneBone(adjacency, fixed_bone, local,
                                        static_cast<int>(vertices.size()), k, &result.dense));
    for (int i : vertices) local[i] = -1;
  }
  for (int i = 0; i < n; ++i) {
    if (fixed_bone[i] >= 0) continue;
    const double sum = result.dense.row(i).sum();
    if (sum <= 1.0) {
      result.dense(i, allowed_bones[i].front()) += 1.0 - sum;
    } else {
      result.dense.row(i) /= sum;
    }
  }
  CompressWeights(&result);
  return result;
}

BoneWeights BoneWeightsFromSkinWeights(const SkinWeights& weights) {
  BoneWeights result;
  result.num_bones = weights.num_bones;
  result.dense = Eigen::MatrixXd::Zero(weights.num_vertices(), weights.num_bones);
  for (int i = 0; i < weights.num_vertices(); ++i) {
    for (int e = weights.offsets[i]; e < weights.offsets[i + 1]; ++e) {
      result.dense(i, weights.bones[e]) += weights.weights[e];
    }
  }
  CompressWeights(&result);
  return result;
}

}  // namespace deform
