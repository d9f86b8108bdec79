#include "core/model/general_rows.h"

#include <algorithm>
#include <cassert>
#include <map>
#include <utility>

#include "core/base/equal_parts.h"

namespace deform {

// Defined in internal/general_rows_kernel_*.cc, where built.
extern const GeneralRowsKernel kBaselineGeneralRowsKernel;
#if defined(DEFORM_HAVE_AVX2_KERNEL)
extern const GeneralRowsKernel kAvx2FmaGeneralRowsKernel;
#endif
#if defined(DEFORM_HAVE_AVX512_KERNEL)
extern const GeneralRowsKernel kAvx512GeneralRowsKernel;
#endif

namespace {

const GeneralRowsKernel& KernelFor(SolveKernel kernel) {
#if defined(DEFORM_HAVE_AVX2_KERNEL)
  if (kernel == SolveKernel::kAvx2Fma) return kAvx2FmaGeneralRowsKernel;
#endif
#if defined(DEFORM_HAVE_AVX512_KERNEL)
  if (kernel == SolveKernel::kAvx512) return kAvx512GeneralRowsKernel;
#endif
  (void)kernel;
  return kBaselineGeneralRowsKernel;
}

// The indices i in [0, count) that keep(i), grouped by their lists lists[offsets[i],
// offsets[i + 1]) (a vertex's or an anchor's bones, in order), ascending within a group; the
// groups in the lists' lexicographic order.
template <typename Keep>
std::map<std::vector<int>, std::vector<int>> GroupByList(const std::vector<int>& offsets,
                                                         const std::vector<int>& lists, int count,
                                                         Keep&& keep) {
  std::map<std::vector<int>, std::vector<int>> groups;
  for (int i = 0; i < count; ++i) {
    if (!keep(i)) continue;
    groups[std::vector<int>(lists.begin() + offsets[i], lists.begin() + offsets[i + 1])].push_back(
        i);
  }
  return groups;
}

int RoundUp(int value, int multiple) { return (value + multiple - 1) / multiple * multiple; }

}  // namespace

GeneralRowsPlan GeneralRowsPlan::Build(const LaplacianSystem& system, const RigidRows& rigid,
                                       const BoneWeights& weights, SolveKernel kernel) {
  GeneralRowsPlan plan;
  plan.kernel_ = KernelFor(SolveKernelAvailable(kernel) ? kernel : SolveKernel::kBaseline);
  const int n = system.num_vertices;

  // The slots: the read vertices grouped by their ordered bone lists, ascending within a group.
  const auto groups = GroupByList(weights.offsets, weights.bones, n,
                                  [&](int j) { return rigid.delta_read[j] != 0; });
  std::vector<int> slot_of(n, -1);
  plan.group_slot_offsets_.push_back(0);
  plan.group_quaternion_offsets_.push_back(0);
  for (const auto& [bones, vertices] : groups) {
    const int begin = static_cast<int>(plan.slot_vertex_.size());
    const int slots = RoundUp(static_cast<int>(vertices.size()), kSlotBlock);
    plan.group_weight_offsets_.push_back(static_cast<int>(plan.weights_.size()));
    for (std::size_t k = 0; k < bones.size(); ++k) {
      for (int l = 0; l < slots; ++l) {
        const bool padding = l >= static_cast<int>(vertices.size());
        // A padding slot blends its first bone alone (a unit quaternion) with a zero delta.
        plan.weights_.push_back(padding ? (k == 0 ? 1.0 : 0.0)
                                        : weights.weights[weights.offsets[vertices[l]] + k]);
      }
      plan.quaternion_bones_.push_back(bones[k]);
      plan.quaternion_first_.push_back(bones[0]);
    }
    for (int l = 0; l < slots; ++l) {
      const int vertex = l < static_cast<int>(vertices.size()) ? vertices[l] : -1;
      if (vertex >= 0) slot_of[vertex] = begin + l;
      plan.slot_vertex_.push_back(vertex);
    }
    plan.group_slot_offsets_.push_back(begin + slots);
    plan.group_quaternion_offsets_.push_back(static_cast<int>(plan.quaternion_bones_.size()));
  }
  plan.slot_count_ = static_cast<int>(plan.slot_vertex_.size());
  plan.deltas_.assign(3 * static_cast<std::size_t>(plan.slot_count_), 0.0);
  for (int s = 0; s < plan.slot_count_; ++s) {
    if (plan.slot_vertex_[s] < 0) continue;
    for (int c = 0; c < 3; ++c) {
      plan.deltas_[static_cast<std::size_t>(c) * plan.slot_count_ + s] =
          system.rest_deltas(plan.slot_vertex_[s], c);
    }
  }

  // The rows: rigid ones listed, general ones packed by length or compressed when long.
  const RowMajorSparseMatrix& lt = system.laplacian_transpose;
  const int rows = static_cast<int>(lt.outerSize());
  const int* row_begin = lt.outerIndexPtr();
  std::vector<std::vector<int>> rows_of_length(kMaxPackedEntries + 1);
  std::map<int, std::vector<int>> rigid_rows_of_bone;
  plan.long_offsets_.push_back(0);
  for (int i = 0; i < rows; ++i) {
    if (rigid.bone_of_row[i] >= 0) {
      rigid_rows_of_bone[rigid.bone_of_row[i]].push_back(i);
      continue;
    }
    const int length = row_begin[i + 1] - row_begin[i];
    if (length <= kMaxPackedEntries) {
      rows_of_length[length].push_back(i);
      continue;
    }
    plan.long_rows_.push_back(i);
    for (int p = row_begin[i]; p < row_begin[i + 1]; ++p) {
      plan.long_columns_.push_back(slot_of[lt.innerIndexPtr()[p]]);
      plan.long_values_.push_back(lt.valuePtr()[p]);
    }
    plan.long_offsets_.push_back(static_cast<int>(plan.long_columns_.size()));
  }
  plan.pack_entry_offsets_.push_back(0);
  for (int length = 0; length <= kMaxPackedEntries; ++length) {
    std::vector<int>& members = rows_of_length[length];
    if (members.empty()) continue;
    members.resize(RoundUp(static_cast<int>(members.size()), kPackRows), members.back());
    for (std::size_t first = 0; first < members.size(); first += kPackRows) {
      for (int e = 0; e < length; ++e) {
        for (int l = 0; l < kPackRows; ++l) {
          const int p = row_begin[members[first + l]] + e;
          plan.pack_columns_.push_back(slot_of[lt.innerIndexPtr()[p]]);
          plan.pack_values_.push_back(lt.valuePtr()[p]);
        }
      }
      plan.pack_rows_.insert(plan.pack_rows_.end(), members.begin() + first,
                             members.begin() + first + kPackRows);
      plan.pack_entry_offsets_.push_back(plan.pack_entry_offsets_.back() + length);
    }
  }
  plan.BuildAnchorGroups(system);
  plan.rigid_offsets_.push_back(0);
  for (auto& [bone, members] : rigid_rows_of_bone) {
    members.resize(RoundUp(static_cast<int>(members.size()), kSlotBlock), members.back());
    plan.rigid_bones_.push_back(bone);
    plan.rigid_rows_.insert(plan.rigid_rows_.end(), members.begin(), members.end());
    plan.rigid_offsets_.push_back(static_cast<int>(plan.rigid_rows_.size()));
  }
  return plan;
}

void GeneralRowsPlan::BuildAnchorGroups(const LaplacianSystem& system) {
  anchor_weight_squared_ = system.anchor_weight * system.anchor_weight;
  const std::size_t count = system.anchors.size();
  const auto groups = GroupByList(system.anchor_offsets, system.anchor_bones,
                                  static_cast<int>(count), [](int) { return true; });
  anchor_rest_.assign(3 * count, 0.0);
  anchor_offsets_.push_back(0);
  anchor_bone_offsets_.push_back(0);
  for (const auto& [group_bones, members] : groups) {
    anchor_weight_offsets_.push_back(static_cast<int>(anchor_weights_.size()));
    for (std::size_t k = 0; k < group_bones.size(); ++k) {
      for (const int a : members) {
        anchor_weights_.push_back(system.anchor_weights[system.anchor_offsets[a] + k]);
      }
    }
    for (const int a : members) {
      const std::size_t at = anchor_rows_.size();
      for (int c = 0; c < 3; ++c) anchor_rest_[c * count + at] = system.anchor_rest(a, c);
      anchor_rows_.push_back(system.anchors[a]);
    }
    anchor_bones_.insert(anchor_bones_.end(), group_bones.begin(), group_bones.end());
    anchor_offsets_.push_back(static_cast<int>(anchor_rows_.size()));
    anchor_bone_offsets_.push_back(static_cast<int>(anchor_bones_.size()));
  }
}

std::vector<double> GeneralRowsPlan::SlotWeights(const Eigen::VectorXd& row_weights_squared) const {
  std::vector<double> slot_weights(slot_count_, 0.0);
  for (int s = 0; s < slot_count_; ++s) {
    if (slot_vertex_[s] >= 0) slot_weights[s] = row_weights_squared[slot_vertex_[s]];
  }
  return slot_weights;
}

void GeneralRowsPlan::SignQuaternions(const std::vector<RigidTransform>& bones,
                                      double* quaternions) const {
  for (int q = 0; q < quaternion_count(); ++q) {
    const Eigen::Quaterniond& rotation = bones[quaternion_bones_[q]].rotation;
    const double sign = bones[quaternion_first_[q]].rotation.dot(rotation) < 0 ? -1.0 : 1.0;
    const Eigen::Vector4d coefficients = sign * rotation.coeffs();  // x, y, z, w
    std::copy_n(coefficients.data(), 4, quaternions + 4 * static_cast<std::ptrdiff_t>(q));
  }
}

SlotGroupsView GeneralRowsPlan::Groups() const {
  SlotGroupsView view;
  view.group_count = static_cast<int>(group_weight_offsets_.size());
  view.slot_count = slot_count_;
  view.slot_offsets = group_slot_offsets_.data();
  view.quaternion_offsets = group_quaternion_offsets_.data();
  view.weight_offsets = group_weight_offsets_.data();
  view.weights = weights_.data();
  view.deltas = deltas_.data();
  return view;
}

RowPacksView GeneralRowsPlan::Packs() const {
  return {pack_entry_offsets_.data(), pack_columns_.data(), pack_values_.data(), pack_rows_.data()};
}

RigidGroupsView GeneralRowsPlan::RigidGroups() const {
  return {static_cast<int>(rigid_bones_.size()), rigid_offsets_.data(), rigid_bones_.data(),
          rigid_rows_.data()};
}

LongRowsView GeneralRowsPlan::LongRows() const {
  return {long_rows_.data(), long_offsets_.data(), long_columns_.data(), long_values_.data()};
}

AnchorGroupsView GeneralRowsPlan::AnchorGroups() const {
  AnchorGroupsView view;
  view.group_count = static_cast<int>(anchor_weight_offsets_.size());
  view.anchor_count = static_cast<int>(anchor_rows_.size());
  view.weight_squared = anchor_weight_squared_;
  view.offsets = anchor_offsets_.data();
  view.bone_offsets = anchor_bone_offsets_.data();
  view.bones = anchor_bones_.data();
  view.weight_offsets = anchor_weight_offsets_.data();
  view.weights = anchor_weights_.data();
  view.rest = anchor_rest_.data();
  view.rows = anchor_rows_.data();
  return view;
}

void GeneralRowsPlan::AddAnchorTargets(const Eigen::Matrix3d* rotations,
                                       const std::vector<RigidTransform>& bones, double* out,
                                       int part, int parts) const {
  const auto [first, end] = EqualPart(static_cast<int>(anchor_rows_.size()), part, parts);
  if (first < end) {
    kernel_.add_anchors(AnchorGroups(), rotations[0].data(), bones.data(), out, first, end);
  }
}

void GeneralRowsPlan::Rotate(const double* quaternions, const double* slot_weights, double* rotated,
                             int part, int parts) const {
  RotateFrames(&quaternions, 1, slot_weights, rotated, part, parts);
}

void GeneralRowsPlan::RotateFrames(const double* const* quaternions, int frames,
                                   const double* slot_weights, double* rotated, int part,
                                   int parts) const {
  assert(frames >= 1 && frames <= kMaxFrames);
  const auto [first, end] = EqualPart(slot_count_ / kSlotBlock, part, parts);
  if (first >= end) return;
  for (int group = 0; group < frames; group += kMaxFramesSideBySide) {
    kernel_.rotate(Groups(), quaternions + group, std::min(kMaxFramesSideBySide, frames - group),
                   slot_weights, rotated + group * rotated_size(), first, end);
  }
}

void GeneralRowsPlan::Multiply(const Eigen::Matrix3d* rotations, const double* rigid_sums,
                               const double* rotated, double* out, int part, int parts) const {
  MultiplyGeneral(rotated, 1, &out, part, parts);
  MultiplyRigid(rotations, rigid_sums, out, part, parts);
}

void GeneralRowsPlan::MultiplyGeneral(const double* rotated, int frames, double* const* outs,
                                      int part, int parts) const {
  assert(frames >= 1 && frames <= kMaxFrames);
  const auto [first_pack, end_pack] = EqualPart(pack_count(), part, parts);
  const auto [first_long, end_long] = EqualPart(static_cast<int>(long_rows_.size()), part, parts);
  for (int group = 0; group < frames; group += kMaxFramesSideBySide) {
    const int count = std::min(kMaxFramesSideBySide, frames - group);
    const double* group_rotated = rotated + group * rotated_size();
    if (first_pack < end_pack) {
      kernel_.multiply(Packs(), group_rotated, count, outs + group, first_pack, end_pack);
    }
    if (first_long < end_long) {
      kernel_.multiply_long(LongRows(), group_rotated, count, outs + group, first_long, end_long);
    }
  }
}

void GeneralRowsPlan::MultiplyRigid(const Eigen::Matrix3d* rotations, const double* rigid_sums,
                                    double* out, int part, int parts) const {
  const auto [first_rigid, end_rigid] =
      EqualPart(static_cast<int>(rigid_rows_.size()) / kSlotBlock, part, parts);
  if (first_rigid < end_rigid) {
    static_assert(sizeof(Eigen::Matrix3d) == 9 * sizeof(double), "matrices packed in an array");
    kernel_.multiply_rigid(RigidGroups(), rotations[0].data(), rigid_sums, out, first_rigid,
                           end_rigid);
  }
}

std::size_t GeneralRowsPlan::bytes() const {
  const auto ints = slot_vertex_.size() + group_slot_offsets_.size() +
                    group_quaternion_offsets_.size() + group_weight_offsets_.size() +
                    quaternion_bones_.size() + quaternion_first_.size() +
                    pack_entry_offsets_.size() + pack_columns_.size() + pack_rows_.size() +
                    long_rows_.size() + long_offsets_.size() + long_columns_.size() +
                    rigid_offsets_.size() + rigid_bones_.size() + rigid_rows_.size();
  const auto anchor_ints = anchor_offsets_.size() + anchor_bone_offsets_.size() +
                           anchor_bones_.size() + anchor_weight_offsets_.size() +
                           anchor_rows_.size();
  const auto doubles = weights_.size() + deltas_.size() + pack_values_.size() +
                       long_values_.size() + anchor_weights_.size() + anchor_rest_.size();
  return (ints + anchor_ints) * sizeof(int) + doubles * sizeof(double);
}

}  // namespace deform
