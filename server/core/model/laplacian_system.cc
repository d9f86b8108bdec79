#include "core/model/laplacian_system.h"

#include <algorithm>
#include <cstddef>

#include "core/model/anchors.h"

namespace deform {
namespace {

// L' (n by n + m): the rows' edge `weights` plus the joint nodes of the vertex, each row summing
// to 0. With uniform weights the arithmetic is the uniform Laplacian's own (1 * share is share).
RowMajorSparseMatrix BuildLaplacian(const WeightedAdjacency& weights, const JointRegions& regions,
                                    int num_nodes, const ModelOptions& options) {
  const int n = static_cast<int>(weights.offsets.size()) - 1;
  std::vector<Eigen::Triplet<double>> triplets;
  triplets.reserve(weights.neighbors.size() + n * 2);
  for (int i = 0; i < n; ++i) {
    const int nodes = options.use_joint_nodes
                          ? regions.membership_offsets[i + 1] - regions.membership_offsets[i]
                          : 0;
    double weight_sum = 0;
    for (int p = weights.offsets[i]; p < weights.offsets[i + 1]; ++p) {
      weight_sum += weights.weights[p];
    }
    // Weight of the edge to each joint node: the row's mean edge weight, or balance times the
    // whole one-ring's.
    const double node_edge = options.joint_node_one_neighbor
                                 ? weight_sum / weights.degree(i)
                                 : options.joint_node_balance * weight_sum;
    const double share = 1.0 / (weight_sum + nodes * node_edge);
    triplets.emplace_back(i, i, 1.0);
    for (int p = weights.offsets[i]; p < weights.offsets[i + 1]; ++p) {
      triplets.emplace_back(i, weights.neighbors[p], -weights.weights[p] * share);
    }
    if (nodes > 0) {
      for (int p = regions.membership_offsets[i]; p < regions.membership_offsets[i + 1]; ++p) {
        triplets.emplace_back(i, n + regions.membership[p], -share * node_edge);
      }
    }
  }
  RowMajorSparseMatrix laplacian(n, n + num_nodes);
  laplacian.setFromTriplets(triplets.begin(), triplets.end());
  laplacian.makeCompressed();
  return laplacian;
}

// L' x_rest, the joint nodes at their regions' centres.
Positions RestDeltas(const TriangleMesh& mesh, const JointRegions& regions,
                     const RowMajorSparseMatrix& laplacian, int num_nodes) {
  const int n = mesh.num_vertices();
  Positions rest_with_nodes(n + num_nodes, 3);
  rest_with_nodes.topRows(n) = mesh.vertices;
  for (int c = 0; c < num_nodes; ++c) {
    rest_with_nodes.row(n + c) = regions.regions[c].centre.transpose();
  }
  return laplacian * rest_with_nodes;
}

}  // namespace

LaplacianSystem BuildLaplacianSystem(const TriangleMesh& mesh, const VertexAdjacency& adjacency,
                                     const JointRegions& regions,
                                     const std::vector<int>& fixed_bone, const BoneWeights& weights,
                                     const ModelOptions& options) {
  LaplacianSystem system;
  system.num_vertices = mesh.num_vertices();
  system.num_nodes = options.use_joint_nodes ? static_cast<int>(regions.regions.size()) : 0;
  for (int c = 0; c < system.num_nodes; ++c) {
    system.node_joints.push_back(regions.regions[c].joint);
  }
  const WeightedAdjacency edge_weights =
      BuildLaplacianWeights(mesh, adjacency, options.laplacian, &system.weight_report);
  system.laplacian = BuildLaplacian(edge_weights, regions, system.num_nodes, options);
  system.laplacian_transpose = system.laplacian.transpose();
  system.laplacian_transpose.makeCompressed();
  system.rest_deltas = RestDeltas(mesh, regions, system.laplacian, system.num_nodes);

  system.anchors = ChooseAnchors(adjacency, fixed_bone, regions, options.anchor_distance_factor,
                                 options.anchor_min_fraction);
  system.anchor_rest.resize(static_cast<Eigen::Index>(system.anchors.size()), 3);
  system.anchor_offsets.assign(1, 0);
  for (std::size_t a = 0; a < system.anchors.size(); ++a) {
    const int i = system.anchors[a];
    for (int e = weights.offsets[i]; e < weights.offsets[i + 1]; ++e) {
      system.anchor_bones.push_back(weights.bones[e]);
      system.anchor_weights.push_back(weights.weights[e]);
    }
    system.anchor_offsets.push_back(static_cast<int>(system.anchor_bones.size()));
    system.anchor_rest.row(a) = mesh.vertices.row(i);
  }
  system.anchor_weight = options.anchor_weight;
  system.node_weight = options.joint_node_weight;
  return system;
}

Eigen::SparseMatrix<double> NormalMatrix(const LaplacianSystem& system,
                                         const Eigen::VectorXd& row_weights_squared) {
  const int n = system.num_vertices;
  RowMajorSparseMatrix weighted = system.laplacian;
  for (int i = 0; i < n; ++i) {
    for (RowMajorSparseMatrix::InnerIterator it(weighted, i); it; ++it) {
      it.valueRef() *= row_weights_squared[i];
    }
  }
  Eigen::SparseMatrix<double> normal = system.laplacian_transpose * weighted;
  const double anchor2 = system.anchor_weight * system.anchor_weight;
  const double node2 = system.node_weight * system.node_weight;
  for (int a : system.anchors) normal.coeffRef(a, a) += anchor2;
  for (int c = 0; c < system.num_nodes; ++c) normal.coeffRef(n + c, n + c) += node2;
  normal.makeCompressed();
  return normal;
}

Eigen::SparseMatrix<double> NormalMatrixPattern(const LaplacianSystem& system) {
  const int n = system.num_vertices;
  Eigen::SparseMatrix<double> pattern = system.laplacian_transpose * system.laplacian;
  for (int a : system.anchors) pattern.coeffRef(a, a) += 1.0;
  for (int c = 0; c < system.num_nodes; ++c) pattern.coeffRef(n + c, n + c) += 1.0;
  pattern.makeCompressed();
  return pattern;
}

void MultiplyLaplacianTranspose(const LaplacianSystem& system, const double* r, double* out) {
  const RowMajorSparseMatrix& lt = system.laplacian_transpose;
  for (int row = 0; row < static_cast<int>(lt.outerSize()); ++row) {
    SparseRowTimes3(lt, r, row, out + 3 * static_cast<std::ptrdiff_t>(row));
  }
}

}  // namespace deform
