// The least-squares system of METHOD.md for one mesh, without its material weights and pose: the
// rows that DeformationModel factorizes and solves (deformation_model.h's notation: n vertices,
// m joint centre nodes, K bones; x holds the n vertices' positions, then the m nodes'):
//
//   vertex rows  w_i ((L' x)_i - T_i delta_i)    delta = L' x_rest, T_i the vertex's rotation blend
//   anchor rows  anchor_weight (x_a - posed a)   an anchor vertex follows its skinning weights
//                                                (rigidly its bone's motion, at weight 1)
//   node rows    node_weight (x_(n+c) - o_c')    joint node c follows its posed joint centre
//
// so that A^T A = L'^T W^2 L' + anchor_weight^2 sum e_a e_a^T + node_weight^2 sum e_c e_c^T and
// A^T b = L'^T (W^2 T delta) + anchor_weight^2 (posed anchors) + node_weight^2 (posed centres).
// Immutable once built.
#pragma once

#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <vector>

#include "core/geometry/mesh.h"
#include "core/geometry/mesh_topology.h"
#include "core/model/bone_weights.h"
#include "core/model/cotangent_weights.h"
#include "core/model/joint_regions.h"
#include "core/model/model_options.h"

namespace deform {

using RowMajorSparseMatrix = Eigen::SparseMatrix<double, Eigen::RowMajor, int>;

struct LaplacianSystem {
  int num_vertices = 0;          // n
  int num_nodes = 0;             // m: one per joint region with options.use_joint_nodes, else none
  std::vector<int> node_joints;  // the joint of each joint node (m)
  // L' (n by n + m), options.laplacian's edge weights (cotangent_weights.h) plus the vertex's joint
  // nodes, compressed by rows; and its transpose for A^T b. Its pattern is the one-ring's except
  // with kIntrinsicCotangent after flips (weight_report.new_neighbor_pairs): everything downstream
  // (the normal matrix, RigidRows, GeneralRowsPlan, the linear response) reads the pattern from
  // here.
  RowMajorSparseMatrix laplacian;
  RowMajorSparseMatrix laplacian_transpose;
  LaplacianWeightReport weight_report;
  Positions rest_deltas;     // delta = L' x_rest, n by 3
  std::vector<int> anchors;  // the anchor vertices, ascending
  // Anchor a's target is sum_e anchor_weights[e] B_(anchor_bones[e]) (rest a) over its entries
  // e in [anchor_offsets[a], anchor_offsets[a + 1]): its own skinning weights (one entry of
  // weight 1 for a vertex of a rigid zone bound automatically).
  std::vector<int> anchor_offsets;
  std::vector<int> anchor_bones;
  std::vector<double> anchor_weights;
  Positions anchor_rest;  // their rest positions, #anchors by 3
  double anchor_weight = 0;
  double node_weight = 0;
};

// Builds the system for `mesh` with its one-ring `adjacency`, joint `regions`, rigid zones
// (`fixed_bone[i]` the bone vertex i belongs to wholly, -1 for none) and bone `weights` (what the
// anchors follow). The rows' edge weights: options.laplacian. A region vertex's row refers
// to its joint nodes with options.joint_node_balance (or as one more neighbour, with
// joint_node_one_neighbor). Anchors: ChooseAnchors (anchors.h) with options.anchor_distance_factor
// and options.anchor_min_fraction.
LaplacianSystem BuildLaplacianSystem(const TriangleMesh& mesh, const VertexAdjacency& adjacency,
                                     const JointRegions& regions,
                                     const std::vector<int>& fixed_bone, const BoneWeights& weights,
                                     const ModelOptions& options);

// Row `row` of m r into target[0..2], for a row-major sparse m and an n by 3 row-major r. Two
// partial sums, so that consecutive entries do not wait on each other's adds. Inline: the
// right-hand side's products call it once per row.
inline void SparseRowTimes3(const RowMajorSparseMatrix& m, const double* __restrict r, int row,
                            double* __restrict target) {
  const int* columns = m.innerIndexPtr();
  const double* values = m.valuePtr();
  double a0 = 0, a1 = 0, a2 = 0, b0 = 0, b1 = 0, b2 = 0;
  int p = m.outerIndexPtr()[row];
  const int end = m.outerIndexPtr()[row + 1];
  for (; p + 2 <= end; p += 2) {
    const double* x = r + 3 * static_cast<std::ptrdiff_t>(columns[p]);
    const double* y = r + 3 * static_cast<std::ptrdiff_t>(columns[p + 1]);
    const double u = values[p], v = values[p + 1];
    a0 += u * x[0];
    a1 += u * x[1];
    a2 += u * x[2];
    b0 += v * y[0];
    b1 += v * y[1];
    b2 += v * y[2];
  }
  if (p < end) {
    const double* x = r + 3 * static_cast<std::ptrdiff_t>(columns[p]);
    a0 += values[p] * x[0];
    a1 += values[p] * x[1];
    a2 += values[p] * x[2];
  }
  target[0] = a0 + b0;
  target[1] = a1 + b1;
  target[2] = a2 + b2;
}

// A^T A ((n + m) square, column-major, compressed) for the vertex rows' squared weights w_i^2 (n).
Eigen::SparseMatrix<double> NormalMatrix(const LaplacianSystem& system,
                                         const Eigen::VectorXd& row_weights_squared);
// A matrix with the pattern of every NormalMatrix of `system` (for the symbolic analysis).
Eigen::SparseMatrix<double> NormalMatrixPattern(const LaplacianSystem& system);

// out = L'^T r: `r` is n by 3 and `out` (n + m) by 3, both row-major. No allocation. (A frame's
// right-hand side takes it through MultiplyRotatedRows, rigid_rows.h.)
void MultiplyLaplacianTranspose(const LaplacianSystem& system, const double* r, double* out);

}  // namespace deform
