// The linear rotation blend of METHOD.md's fast path, made close to the quaternion blend on any
// number of bones per vertex.
//
// Every vertex's blend T_i is a fixed linear combination of "slot" rotations: slot k < K is bone
// k's rotation R_k, slot K + j is knot j. A knot is the quaternion blend of a few bones at fixed
// shares, normalize(sum_k g_k q_k) with the g_k non-negative integers summing to S (the
// `segments`), the signs of the q_k aligned to the knot's first bone: a point of the simplex grid
// of resolution S over the bones' weights. A vertex with weights w on its m bones (taken in
// ascending bone order) lies in one cell of the Freudenthal (Kuhn) triangulation of that grid, in
// the cumulative coordinates c_j = S (w_0 + ... + w_j); T_i interpolates linearly between the
// rotations of the cell's m corners, with the vertex's barycentric coordinates in the cell.
//
// So a vertex of two bones interpolates between neighbouring samples s = j / S of the pair's
// quaternion blend, one of three or more bones between neighbouring grid points of their
// quaternion blend; S = 1 is METHOD.md's plain linear blend sum_k w_k R_k. The blended matrix's
// scale tends to 1 as S grows (at most 1 - cos(angle between neighbouring corners / 2) below),
// while T_i stays linear in the slot rotations, which is what the precomputed response needs. The
// coefficients of every vertex sum to 1, so a rigid motion of the whole skeleton is exact.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <utility>
#include <vector>

#include "core/geometry/pose.h"
#include "core/model/bone_weights.h"

namespace deform {

class LinearBlendPlan {
 public:
  // The plan of `bone_weights` (K = num_bones) at `segments` S >= 1. Builds only what some vertex
  // uses: a knot exists when a vertex's cell has it as a corner with a coefficient of 1e-12 or more
  // (smaller coefficients are added to the cell's largest, so the sum stays 1).
  static LinearBlendPlan Build(const BoneWeights& bone_weights, int num_bones, int segments);

  int segments() const { return segments_; }
  int num_bones() const { return num_bones_; }
  int num_knots() const { return static_cast<int>(knot_offsets_.size()) - 1; }
  int num_slots() const { return num_bones_ + num_knots(); }
  int num_vertices() const { return static_cast<int>(term_offsets_.size()) - 1; }

  // Vertex i's T_i = sum over terms t in [term_begin(i), term_end(i)) of
  // term_coefficient(t) * (the rotation of slot term_slot(t)).
  int term_begin(int vertex) const { return term_offsets_[vertex]; }
  int term_end(int vertex) const { return term_offsets_[vertex + 1]; }
  int term_slot(int term) const { return term_slots_[term]; }
  double term_coefficient(int term) const { return term_coefficients_[term]; }

  // Knot j's bones and their integer shares (summing to segments()), bones ascending.
  std::vector<std::pair<int, int>> KnotShares(int knot) const;

  // Knot j's rotation for these bone transforms (one per skeleton bone). No allocation.
  Eigen::Quaterniond KnotRotation(int knot, const std::vector<RigidTransform>& bones) const;

  // rotations[0, num_slots()) = every slot's rotation as a matrix. No allocation.
  void SlotRotations(const std::vector<RigidTransform>& bones, Eigen::Matrix3d* rotations) const;

  // The blend of `vertex` from the slot rotations SlotRotations() filled.
  Eigen::Matrix3d Blend(int vertex, const Eigen::Matrix3d* slot_rotations) const;

 private:
  int segments_ = 1;
  int num_bones_ = 0;
  // Knot j's bones and integer shares: [knot_offsets_[j], knot_offsets_[j + 1]), bones ascending.
  std::vector<int> knot_offsets_{0};
  std::vector<int> knot_bones_;
  std::vector<int> knot_shares_;
  // Per vertex, its terms (CSR).
  std::vector<int> term_offsets_{0};
  std::vector<int> term_slots_;
  std::vector<double> term_coefficients_;
};

// The cell of the simplex grid of resolution `segments` S that holds the weights `weights` (m >= 1
// of them, non-negative, summing to 1; in the order the grid's coordinates take): its m corners as
// integer shares (corner c's shares at corner_shares[c * m, (c + 1) * m), summing to S) and the
// weights' barycentric coordinates in it (`coefficients`, m, non-negative, summing to 1). For m = 2
// the corners are the two samples j / S around the second weight.
void SimplexGridCell(const std::vector<double>& weights, int segments,
                     std::vector<int>* corner_shares, std::vector<double>* coefficients);

}  // namespace deform
