// The rotation blends of a vertex near a joint, shared by the right-hand side (per vertex) and the
// linear response (per knot), so both compute the same T_i.
//
// Piecewise-linear blend of a bone pair (a, b), `segments` S >= 1: the pair's quaternion blend
// QLERP(q_a, q_b; s) = normalise((1 - s) q_a + s q_b) is sampled at the S + 1 knots s = j / S
// (knot 0 is R_a, knot S is R_b), and a vertex with weight h on b takes the linear blend of the
// two knots around h. S = 1 is the plain linear blend (1 - h) R_a + h R_b; the blended matrix's
// scale, cos of half the angle between neighbouring knots, tends to 1 as S grows, so the blend
// tends to the quaternion blend while staying linear in the knot rotations.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

namespace deform {

// A vertex's two bones ordered by index (the order knots are numbered in) and the weight of the
// second.
struct BonePair {
  int a = 0;
  int b = 0;
  double h = 0;  // weight of b
};

inline BonePair OrderedPair(int bone0, double weight0, int bone1, double weight1) {
  return bone0 < bone1 ? BonePair{bone0, bone1, weight1} : BonePair{bone1, bone0, weight0};
}

// The two knots around weight h in [0, 1] and the weight of the upper one.
struct PairSegment {
  int lower = 0;            // knot index j in [0, S - 1]; the upper knot is j + 1
  double upper_weight = 0;  // u: T = (1 - u) R_j + u R_(j+1)
};

inline PairSegment SegmentOf(double h, int segments) {
  const double t = std::clamp(h, 0.0, 1.0) * segments;
  const int lower = std::min(static_cast<int>(std::floor(t)), segments - 1);
  return {lower, t - lower};
}

// QLERP(q_a, q_b; s) with q_b's sign chosen on q_a's side (as the vertex blend does).
inline Eigen::Quaterniond PairKnot(const Eigen::Quaterniond& a, const Eigen::Quaterniond& b,
                                   double s) {
  const double sign = a.dot(b) < 0 ? -1.0 : 1.0;
  Eigen::Quaterniond q;
  q.coeffs() = (1 - s) * a.coeffs() + (sign * s) * b.coeffs();
  return q.normalized();
}

}  // namespace deform
