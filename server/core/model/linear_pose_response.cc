#include "core/model/linear_pose_response.h"

#include <algorithm>
#include <cassert>
#include <memory>
#include <utility>

#include "core/base/cpu_features.h"
#include "core/geometry/rotated_fields.h"

namespace deform {
namespace {

// Vertices per block: the block's three coordinate accumulators (6 KB) stay in L1 while every
// response vector streams through once.
constexpr int kBlock = 256;

// The whole evaluation, written once and compiled for AVX2 + FMA and for any x86-64 (or other)
// CPU; Evaluate() picks one at run time.
DEFORM_ALWAYS_INLINE void EvaluateBlocks(int n, const std::vector<int>& bones,
                                         const LinearBlendPlan& plan, const double* columns,
                                         const std::vector<RigidTransform>& transforms,
                                         double* positions) {
  const std::size_t stride = static_cast<std::size_t>(n);
  const double* knot_columns = columns + 4 * bones.size() * stride;
  alignas(64) double x[kBlock];
  alignas(64) double y[kBlock];
  alignas(64) double z[kBlock];
  for (int begin = 0; begin < n; begin += kBlock) {
    const int count = std::min(kBlock, n - begin);
    std::fill_n(x, count, 0.0);
    std::fill_n(y, count, 0.0);
    std::fill_n(z, count, 0.0);
    for (std::size_t b = 0; b < bones.size(); ++b) {
      const RigidTransform& transform = transforms[bones[b]];
      const double* u = columns + 4 * b * stride + begin;
      AddRotatedField(transform.rotation.toRotationMatrix(), u, stride, count, x, y, z);
      const Eigen::Vector3d& t = transform.translation;
      AddScaledColumn(u + 3 * stride, count, t.x(), t.y(), t.z(), x, y, z);
    }
    for (int k = 0; k < plan.num_knots(); ++k) {
      AddRotatedField(plan.KnotRotation(k, transforms).toRotationMatrix(),
                      knot_columns + 3 * static_cast<std::size_t>(k) * stride + begin, stride,
                      count, x, y, z);
    }
    double* out = positions + 3 * static_cast<std::size_t>(begin);
    for (int i = 0; i < count; ++i) {
      out[3 * i] = x[i];
      out[3 * i + 1] = y[i];
      out[3 * i + 2] = z[i];
    }
  }
}

#if defined(__x86_64__) && defined(__GNUC__)
__attribute__((target("avx2,fma"))) void EvaluateAvx2(int n, const std::vector<int>& bones,
                                                      const LinearBlendPlan& plan,
                                                      const double* columns,
                                                      const std::vector<RigidTransform>& transforms,
                                                      double* positions) {
  EvaluateBlocks(n, bones, plan, columns, transforms, positions);
}

#endif

}  // namespace

LinearPoseResponse::LinearPoseResponse(int num_vertices, std::vector<int> bones,
                                       std::shared_ptr<const LinearBlendPlan> plan,
                                       std::vector<double> columns)
    : num_vertices_(num_vertices),
      bones_(std::move(bones)),
      plan_(std::move(plan)),
      columns_(std::move(columns)) {
  assert(columns_.size() == (4 * bones_.size() + 3 * static_cast<std::size_t>(num_knots())) *
                                static_cast<std::size_t>(num_vertices_));
}

void LinearPoseResponse::Evaluate(const std::vector<RigidTransform>& bone_transforms,
                                  double* positions) const {
#if defined(__x86_64__) && defined(__GNUC__)
  if (CpuHasAvx2Fma()) {
    EvaluateAvx2(num_vertices_, bones_, *plan_, columns_.data(), bone_transforms, positions);
    return;
  }
#endif
  EvaluateBlocks(num_vertices_, bones_, *plan_, columns_.data(), bone_transforms, positions);
}

// ---------------------------------------------------------------------------------------------
// Building the response

namespace {

// The rotations the response is linear in ("slots"): first each bone that reaches the right-hand
// side (with its translation), then the blend plan's knots.
struct ResponseSlots {
  std::vector<int> bones;      // the bone of each bone slot, ascending
  std::vector<int> bone_slot;  // per bone, its slot or -1
  int num_knots = 0;           // knot k is slot bones.size() + k
  // Per vertex, T_i = sum of coefficient * (the slot's rotation).
  std::vector<std::vector<std::pair<int, double>>> vertex_terms;

  int num_bone_slots() const { return static_cast<int>(bones.size()); }
  int num_slots() const { return num_bone_slots() + num_knots; }
  // Doubles of the response: four vectors per bone, three per knot, n each.
  std::size_t response_doubles(int n) const {
    return (4 * bones.size() + 3 * static_cast<std::size_t>(num_knots)) *
           static_cast<std::size_t>(n);
  }
  // Where slot `slot`'s vectors start among them (linear_pose_response.h's order).
  std::size_t offset(int slot, int n) const {
    const std::size_t stride = static_cast<std::size_t>(n);
    return slot < num_bone_slots() ? 4 * slot * stride
                                   : (4 * bones.size() + 3 * (slot - num_bone_slots())) * stride;
  }
};

// The bone slots: bones that appear in the right-hand side at all, through blend weights, anchors
// and joint nodes. False when a joint node moves with the root transform (inner joints never do).
bool FindBoneSlots(const LaplacianSystem& system, const LinearBlendPlan& plan,
                   const std::vector<int>& node_bones, int num_bones, ResponseSlots* slots) {
  std::vector<char> appears(num_bones, 0);
  for (int t = 0; t < plan.term_begin(plan.num_vertices()); ++t) {
    if (plan.term_slot(t) < num_bones) appears[plan.term_slot(t)] = 1;
  }

  for (int k : system.anchor_bones) appears[k] = 1;
  for (int k : node_bones) {
    if (k < 0) return false;
    appears[k] = 1;
  }
  slots->bone_slot.assign(num_bones, -1);
  for (int k = 0; k < num_bones; ++k) {
    if (!appears[k]) continue;
    slots->bone_slot[k] = static_cast<int>(slots->bones.size());
    slots->bones.push_back(k);
  }
  return true;
}

// Each vertex's terms in response slots (the plan's bone slot k -> bone_slot[k], knot j -> the
// j-th knot slot).
void AddBlendTerms(const LinearBlendPlan& plan, ResponseSlots* slots) {
  const int n = plan.num_vertices();
  slots->num_knots = plan.num_knots();
  slots->vertex_terms.assign(n, {});
  for (int i = 0; i < n; ++i) {
    for (int t = plan.term_begin(i); t < plan.term_end(i); ++t) {
      const int slot = plan.term_slot(t);
      const int response_slot = slot < plan.num_bones()
                                    ? slots->bone_slot[slot]
                                    : slots->num_bone_slots() + slot - plan.num_bones();
      slots->vertex_terms[i].emplace_back(response_slot, plan.term_coefficient(t));
    }
  }
}

// Solves for the response vectors of one slot at a time, reusing its buffers. Column b of a
// slot's U solves A u = (the right-hand side of that rotation = I, every other transform zero)'s
// column b, since right-hand side coordinate a is sum over slots sum_b R[a, b] (that column) + sum
// over bones t_k[a] (V_k's); see the top of linear_pose_response.h.
class ResponseSolver {
 public:
  ResponseSolver(const LaplacianSystem& system, const Skeleton& skeleton,
                 const std::vector<int>& node_bones, const Eigen::VectorXd& row_weights_squared,
                 const CholeskyFactor& factor)
      : system_(system),
        skeleton_(skeleton),
        node_bones_(node_bones),
        row_weights_squared_(row_weights_squared),
        factor_(factor),
        weighted_deltas_(system.num_vertices, 3),
        rhs_(system.num_vertices + system.num_nodes, 3),
        work_(factor.WorkSize()) {}

  // U_0, U_1, U_2 of `slot` (the bone `bone`'s, or -1 for a knot) into response[0, 3 n).
  bool SolveRotation(int slot, int bone, const ResponseSlots& slots, double* response) {
    const int n = system_.num_vertices;
    weighted_deltas_.setZero();
    for (int i = 0; i < n; ++i) {
      for (const auto& [term_slot, coefficient] : slots.vertex_terms[i]) {
        if (term_slot == slot) {
          weighted_deltas_.row(i) +=
              row_weights_squared_[i] * coefficient * system_.rest_deltas.row(i);
        }
      }
    }
    MultiplyLaplacianTranspose(system_, weighted_deltas_.data(), rhs_.data());
    AddConstraints(bone, [](const Eigen::RowVector3d& rest) { return rest; });
    if (!factor_.Solve3(rhs_.data(), rhs_.data(), work_.data()).ok()) return false;
    const std::size_t stride = static_cast<std::size_t>(n);
    for (int b = 0; b < 3; ++b) {
      for (int i = 0; i < n; ++i) response[b * stride + i] = rhs_(i, b);
    }
    return true;
  }

  // V of bone `bone`: t = 1 (the same scalar response for each coordinate), every rotation zero,
  // into response[0, n).
  bool SolveTranslation(int bone, double* response) {
    rhs_.setZero();
    AddConstraints(bone, [](const Eigen::RowVector3d&) { return Eigen::RowVector3d(1, 0, 0); });
    if (!factor_.Solve3(rhs_.data(), rhs_.data(), work_.data()).ok()) return false;
    for (int i = 0; i < system_.num_vertices; ++i) response[i] = rhs_(i, 0);
    return true;
  }

 private:
  // The right-hand side rows of the anchors and joint nodes that follow `bone` += their weight^2 *
  // (an anchor's skinning weight on `bone`) * target(their rest position).
  template <typename Target>
  void AddConstraints(int bone, const Target& target) {
    const int n = system_.num_vertices;
    const double anchor2 = system_.anchor_weight * system_.anchor_weight;
    const double node2 = system_.node_weight * system_.node_weight;
    for (std::size_t a = 0; a < system_.anchors.size(); ++a) {
      for (int e = system_.anchor_offsets[a]; e < system_.anchor_offsets[a + 1]; ++e) {
        if (system_.anchor_bones[e] == bone) {
          rhs_.row(system_.anchors[a]) +=
              (anchor2 * system_.anchor_weights[e]) * target(system_.anchor_rest.row(a));
        }
      }
    }
    for (int c = 0; c < system_.num_nodes; ++c) {
      if (node_bones_[c] == bone) {
        rhs_.row(n + c) +=
            node2 * target(skeleton_.joint(system_.node_joints[c]).rest_position.transpose());
      }
    }
  }

  const LaplacianSystem& system_;
  const Skeleton& skeleton_;
  const std::vector<int>& node_bones_;
  const Eigen::VectorXd& row_weights_squared_;
  const CholeskyFactor& factor_;
  Positions weighted_deltas_;
  Positions rhs_;
  std::vector<double> work_;
};

}  // namespace

std::unique_ptr<const LinearPoseResponse> BuildLinearPoseResponse(
    const LaplacianSystem& system, const Skeleton& skeleton,
    const std::shared_ptr<const LinearBlendPlan>& plan, const Eigen::VectorXd& row_weights_squared,
    const CholeskyFactor& factor) {
  const int n = system.num_vertices;
  std::vector<int> node_bones(system.num_nodes);
  for (int c = 0; c < system.num_nodes; ++c) {
    node_bones[c] = skeleton.IncomingBone(system.node_joints[c]);
  }
  ResponseSlots slots;
  if (!FindBoneSlots(system, *plan, node_bones, skeleton.num_bones(), &slots)) return nullptr;
  AddBlendTerms(*plan, &slots);
  // A frame reads the response once, a solve reads the factor twice: build it when it reads less.
  const std::size_t response_doubles = slots.response_doubles(n);
  if (response_doubles >= 2 * static_cast<std::size_t>(factor.nonzeros())) return nullptr;

  std::vector<double> columns(response_doubles);
  ResponseSolver solver(system, skeleton, node_bones, row_weights_squared, factor);
  for (int slot = 0; slot < slots.num_slots(); ++slot) {
    const bool is_bone = slot < slots.num_bone_slots();
    const int bone = is_bone ? slots.bones[slot] : -1;
    double* response = columns.data() + slots.offset(slot, n);
    if (!solver.SolveRotation(slot, bone, slots, response)) return nullptr;
    if (is_bone && !solver.SolveTranslation(bone, response + 3 * static_cast<std::size_t>(n))) {
      return nullptr;
    }
  }
  return std::make_unique<LinearPoseResponse>(n, std::move(slots.bones), plan, std::move(columns));
}

}  // namespace deform
