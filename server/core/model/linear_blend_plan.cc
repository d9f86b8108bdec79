#include "core/model/linear_blend_plan.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <numeric>
#include <utility>

namespace deform {

void SimplexGridCell(const std::vector<double>& weights, int segments,
                     std::vector<int>* corner_shares, std::vector<double>* coefficients) {
  const int m = static_cast<int>(weights.size());
  const int dims = m - 1;  // cumulative coordinates c_j = S (w_0 + ... + w_j), j < m - 1
  std::vector<int> base(dims);
  std::vector<double> fraction(dims);
  double cumulative = 0;
  for (int j = 0; j < dims; ++j) {
    cumulative += weights[j];
    const double c = std::clamp(cumulative * segments, 0.0, static_cast<double>(segments));
    base[j] = std::min(static_cast<int>(std::floor(c)), segments - 1);
    fraction[j] = c - base[j];
  }
  // Kuhn's simplex: step the coordinates up one at a time, largest fraction first. Ties go to the
  // later coordinate first, which keeps every corner's coordinates non-decreasing (a grid point).
  std::vector<int> order(dims);
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) {
    return fraction[a] > fraction[b] || (fraction[a] == fraction[b] && a > b);
  });
  corner_shares->assign(static_cast<std::size_t>(m) * m, 0);
  coefficients->assign(m, 0.0);
  std::vector<int> corner = base;
  for (int c = 0; c < m; ++c) {
    if (c > 0) corner[order[c - 1]] += 1;
    int* shares = corner_shares->data() + static_cast<std::size_t>(c) * m;
    int previous = 0;
    for (int j = 0; j < dims; ++j) {
      shares[j] = corner[j] - previous;
      previous = corner[j];
    }
    shares[dims] = segments - previous;
    const double upper = c == 0 ? 1.0 : fraction[order[c - 1]];
    const double lower = c == dims ? 0.0 : fraction[order[c]];
    (*coefficients)[c] = upper - lower;
  }
}

namespace {

constexpr double kDropCoefficientBelow = 1e-12;

// Grid points as (bone, share) lists with the zero shares left out, bones ascending.
using GridPoint = std::vector<std::pair<int, int>>;

}  // namespace

LinearBlendPlan LinearBlendPlan::Build(const BoneWeights& bone_weights, int num_bones,
                                       int segments) {
  LinearBlendPlan plan;
  plan.segments_ = segments;
  plan.num_bones_ = num_bones;
  std::map<GridPoint, int> knot_of_point;
  std::vector<std::pair<int, double>> bones_ascending;
  std::vector<double> weights;
  std::vector<int> corner_shares;
  std::vector<double> coefficients;
  for (int i = 0; i < bone_weights.num_vertices(); ++i) {
    bones_ascending.clear();
    for (int p = bone_weights.offsets[i]; p < bone_weights.offsets[i + 1]; ++p) {
      bones_ascending.emplace_back(bone_weights.bones[p], bone_weights.weights[p]);
    }
    std::sort(bones_ascending.begin(), bones_ascending.end());
    const int m = static_cast<int>(bones_ascending.size());
    weights.clear();
    for (const auto& entry : bones_ascending) weights.push_back(entry.second);
    SimplexGridCell(weights, segments, &corner_shares, &coefficients);
    // Coefficients too small to matter go to the largest, so the sum stays 1.
    const int largest = static_cast<int>(
        std::max_element(coefficients.begin(), coefficients.end()) - coefficients.begin());
    for (int c = 0; c < m; ++c) {
      if (c != largest && coefficients[c] < kDropCoefficientBelow) {
        coefficients[largest] += coefficients[c];
        coefficients[c] = 0;
      }
    }
    for (int c = 0; c < m; ++c) {
      if (coefficients[c] == 0) continue;
      GridPoint point;
      for (int j = 0; j < m; ++j) {
        const int share = corner_shares[static_cast<std::size_t>(c) * m + j];
        if (share > 0) point.emplace_back(bones_ascending[j].first, share);
      }
      int slot = point.front().first;  // a corner of the whole simplex: the bone itself
      if (point.size() > 1) {
        const auto [it, inserted] = knot_of_point.emplace(point, plan.num_knots());
        if (inserted) {
          for (const auto& [bone, share] : point) {
            plan.knot_bones_.push_back(bone);
            plan.knot_shares_.push_back(share);
          }
          plan.knot_offsets_.push_back(static_cast<int>(plan.knot_bones_.size()));
        }
        slot = num_bones + it->second;
      }
      plan.term_slots_.push_back(slot);
      plan.term_coefficients_.push_back(coefficients[c]);
    }
    plan.term_offsets_.push_back(static_cast<int>(plan.term_slots_.size()));
  }
  return plan;
}

std::vector<std::pair<int, int>> LinearBlendPlan::KnotShares(int knot) const {
  std::vector<std::pair<int, int>> shares;
  for (int p = knot_offsets_[knot]; p < knot_offsets_[knot + 1]; ++p) {
    shares.emplace_back(knot_bones_[p], knot_shares_[p]);
  }
  return shares;
}

Eigen::Quaterniond LinearBlendPlan::KnotRotation(int knot,
                                                 const std::vector<RigidTransform>& bones) const {
  const int begin = knot_offsets_[knot], end = knot_offsets_[knot + 1];
  const Eigen::Quaterniond& first = bones[knot_bones_[begin]].rotation;
  Eigen::Quaterniond q;
  q.coeffs() = static_cast<double>(knot_shares_[begin]) * first.coeffs();
  for (int p = begin + 1; p < end; ++p) {
    const Eigen::Quaterniond& qk = bones[knot_bones_[p]].rotation;
    const double sign = first.dot(qk) < 0 ? -1.0 : 1.0;
    q.coeffs() += (sign * knot_shares_[p]) * qk.coeffs();
  }
  return q.normalized();
}

void LinearBlendPlan::SlotRotations(const std::vector<RigidTransform>& bones,
                                    Eigen::Matrix3d* rotations) const {
  for (int k = 0; k < num_bones_; ++k) rotations[k] = bones[k].rotation.toRotationMatrix();
  for (int j = 0; j < num_knots(); ++j) {
    rotations[num_bones_ + j] = KnotRotation(j, bones).toRotationMatrix();
  }
}

Eigen::Matrix3d LinearBlendPlan::Blend(int vertex, const Eigen::Matrix3d* slot_rotations) const {
  Eigen::Matrix3d blend = Eigen::Matrix3d::Zero();
  for (int t = term_begin(vertex); t < term_end(vertex); ++t) {
    blend += term_coefficient(t) * slot_rotations[term_slot(t)];
  }
  return blend;
}

}  // namespace deform
