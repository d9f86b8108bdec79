#include "core/eval/direct_delta_mush.h"

#include <Eigen/Geometry>
#include <Eigen/SVD>
#include <algorithm>

#include "core/geometry/mesh_topology.h"

namespace deform {
namespace {

constexpr int kColumns = 14;  // 10 for Omega's upper triangle, 4 for omega

// The position in the 10-vector of Omega's entry (r, c) of the symmetric 4x4 matrix.
constexpr int UpperIndex(int r, int c) {
  return r <= c ? r * 4 - r * (r - 1) / 2 + (c - r) : c * 4 - c * (c - 1) / 2 + (r - c);
}

using Columns = Eigen::Matrix<double, Eigen::Dynamic, kColumns, Eigen::RowMajor>;

// `iterations` explicit smoothing steps x <- (1 - step) x + step * (mean of the neighbours) on
// the columns [first, first + count) of *values, with *work as the other buffer (same shape).
void Smooth(const VertexAdjacency& adjacency, int iterations, double step, int first, int count,
            Columns* values, Columns* work) {
  const int n = static_cast<int>(values->rows());
  for (int iteration = 0; iteration < iterations; ++iteration) {
    for (int i = 0; i < n; ++i) {
      const int degree = adjacency.degree(i);
      for (int c = first; c < first + count; ++c) {
        double mean = 0;
        for (int e = adjacency.offsets[i]; e < adjacency.offsets[i + 1]; ++e) {
          mean += (*values)(adjacency.neighbors[e], c);
        }
        mean = degree > 0 ? mean / degree : (*values)(i, c);
        (*work)(i, c) = (1 - step) * (*values)(i, c) + step * mean;
      }
    }
    for (int i = 0; i < n; ++i) {
      for (int c = first; c < first + count; ++c) (*values)(i, c) = (*work)(i, c);
    }
  }
}

}  // namespace

DirectDeltaMush DirectDeltaMush::Precompute(const TriangleMesh& mesh, const BoneWeights& weights,
                                            const DirectDeltaMushOptions& options) {
  DirectDeltaMush result;
  result.options_ = options;
  const int n = mesh.num_vertices();
  result.num_bones_ = weights.num_bones;
  result.center_ = 0.5 * (mesh.vertices.colwise().minCoeff().transpose() +
                          mesh.vertices.colwise().maxCoeff().transpose());
  result.centred_rest_ = mesh.vertices.rowwise() - result.center_.transpose();
  const VertexAdjacency adjacency = BuildVertexAdjacency(mesh.triangles, n);

  // Bone after bone: its weighted u u^T and u, smoothed, kept where non-zero.
  struct Found {
    int vertex;
    int bone;
    Entry entry;
  };
  std::vector<Found> found;
  Columns values(n, kColumns), work(n, kColumns);
  for (int j = 0; j < weights.num_bones; ++j) {
    values.setZero();
    bool any = false;
    for (int i = 0; i < n; ++i) {
      double w = 0;
      for (int p = weights.offsets[i]; p < weights.offsets[i + 1]; ++p) {
        if (weights.bones[p] == j) w = weights.weights[p];
      }
      if (w == 0) continue;
      any = true;
      Eigen::Vector4d u;
      u << result.centred_rest_.row(i).transpose(), 1.0;
      for (int r = 0; r < 4; ++r) {
        for (int c = r; c < 4; ++c) values(i, UpperIndex(r, c)) = w * u[r] * u[c];
        values(i, 10 + r) = w * u[r];
      }
    }
    if (!any) continue;
    Smooth(adjacency, options.rotation_iterations, options.step, 0, 10, &values, &work);
    Smooth(adjacency, options.translation_iterations, options.step, 10, 4, &values, &work);
    for (int i = 0; i < n; ++i) {
      // The masses (sum_k B_ik w_kj) are non-negative; where both are 0 the bone is absent.
      if (values(i, UpperIndex(3, 3)) == 0 && values(i, 13) == 0) continue;
      Found f{i, j, {}};
      for (int c = 0; c < 10; ++c) f.entry.rotation[c] = values(i, c);
      for (int c = 0; c < 4; ++c) f.entry.translation[c] = values(i, 10 + c);
      found.push_back(f);
    }
  }
  // Grouped by vertex, bones ascending within each (a stable counting sort).
  result.offsets_.assign(n + 1, 0);
  for (const Found& f : found) ++result.offsets_[f.vertex + 1];
  for (int i = 0; i < n; ++i) result.offsets_[i + 1] += result.offsets_[i];
  result.bones_.resize(found.size());
  result.entries_.resize(found.size());
  std::vector<int> next(result.offsets_.begin(), result.offsets_.end() - 1);
  for (const Found& f : found) {
    const int slot = next[f.vertex]++;
    result.bones_[slot] = f.bone;
    result.entries_[slot] = f.entry;
  }
  return result;
}

void DirectDeltaMush::Deform(const std::vector<RigidTransform>& bone_transforms, Positions* posed,
                             BoneMatrices* bone_matrices) const {
  const int n = static_cast<int>(centred_rest_.rows());
  posed->resize(n, 3);
  bone_matrices->resize(num_bones_);
  // Each bone's transform on centred coordinates: x = R (u + c) + t = R u + (R c + t).
  for (int j = 0; j < num_bones_; ++j) {
    const Eigen::Matrix3d rotation = bone_transforms[j].rotation.normalized().toRotationMatrix();
    (*bone_matrices)[j].leftCols<3>() = rotation;
    (*bone_matrices)[j].col(3) = rotation * center_ + bone_transforms[j].translation;
  }
  for (int i = 0; i < n; ++i) {
    Eigen::Matrix<double, 3, 4> q_rotation = Eigen::Matrix<double, 3, 4>::Zero();
    Eigen::Vector4d bottom = Eigen::Vector4d::Zero();
    Eigen::Vector3d q_translation = Eigen::Vector3d::Zero();
    Eigen::Vector4d translation_bottom = Eigen::Vector4d::Zero();
    for (int e = offsets_[i]; e < offsets_[i + 1]; ++e) {
      const Entry& entry = entries_[e];
      Eigen::Matrix4d omega;
      for (int r = 0; r < 4; ++r) {
        for (int c = 0; c < 4; ++c) omega(r, c) = entry.rotation[UpperIndex(r, c)];
      }
      const Eigen::Map<const Eigen::Vector4d> small_omega(entry.translation);
      const Eigen::Matrix<double, 3, 4>& bone = (*bone_matrices)[bones_[e]];
      q_rotation.noalias() += bone * omega;
      bottom += omega.row(3).transpose();
      q_translation.noalias() += bone * small_omega;
      translation_bottom += small_omega;
    }
    const Eigen::Vector3d p = bottom.head<3>() / bottom[3];
    const Eigen::Vector3d q = q_rotation.col(3) / bottom[3];
    const Eigen::Matrix3d covariance = q_rotation.leftCols<3>() / bottom[3] - q * p.transpose();
    const Eigen::JacobiSVD<Eigen::Matrix3d> svd(covariance,
                                                Eigen::ComputeFullU | Eigen::ComputeFullV);
    Eigen::Matrix3d u = svd.matrixU();
    Eigen::Matrix3d rotation = u * svd.matrixV().transpose();
    if (rotation.determinant() < 0) {
      u.col(2) = -u.col(2);  // the smallest singular value's: the closest proper rotation
      rotation = u * svd.matrixV().transpose();
    }
    const Eigen::Vector3d p_translation = translation_bottom.head<3>() / translation_bottom[3];
    const Eigen::Vector3d t = q_translation / translation_bottom[3] - rotation * p_translation;
    posed->row(i) = (rotation * centred_rest_.row(i).transpose() + t).transpose();
  }
}

}  // namespace deform
