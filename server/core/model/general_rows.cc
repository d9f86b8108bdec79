#include "core/model/general_rows.h"

#include <algorithm>
#include <cstdint>
#include <map>
#include <utility>

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

// [count * part / parts, count * (part + 1) / parts).
std::pair<int, int> PartOf(int count, int part, int parts) {
  const auto at = [&](int i) {
    return static_cast<int>(static_cast<std::int64_t>(count) * i / parts);
  };
  return {at(part), at(part + 1)};
}

int RoundUp(int value, int multiple) { return (value + multiple - 1) / multiple * multiple; }

}  // namespace

GeneralRowsPlan GeneralRowsPlan::Build(const LaplacianSystem& system, const RigidRows& rigid,
                                       const BoneWeights& weights, SolveKernel kernel) {
  GeneralRowsPlan plan;
  plan.kernel_ = KernelFor(SolveKernelAvailable(kernel) ? kernel : SolveKernel::kBaseline);
  const int n = system.num_vertices;

  // The slots: the read vertices grouped by their ordered bone lists, ascending within a group.
  std::map<std::vector<int>, std::vector<int>> groups;
  for (int j = 0; j < n; ++j) {
    if (!rigid.delta_read[j]) continue;
    const auto bones_begin = weights.bones.begin();
    groups[std::vector<int>(bones_begin + weights.offsets[j], bones_begin + weights.offsets[j + 1])]
        .push_back(j);
  }
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
  plan.long_offsets_.push_back(0);
  for (int i = 0; i < rows; ++i) {
    if (rigid.bone_of_row[i] >= 0) {
      plan.rigid_rows_.push_back(i);
      plan.rigid_bones_.push_back(rigid.bone_of_row[i]);
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
  return plan;
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

void GeneralRowsPlan::Rotate(const double* quaternions, const double* slot_weights, double* rotated,
                             int part, int parts) const {
  const auto [first, end] = PartOf(slot_count_ / kSlotBlock, part, parts);
  if (first < end) kernel_.rotate(Groups(), quaternions, slot_weights, rotated, first, end);
}

void GeneralRowsPlan::Multiply(const Eigen::Matrix3d* rotations, const double* rigid_sums,
                               const double* rotated, double* out, int part, int parts) const {
  const auto [first_pack, end_pack] = PartOf(pack_count(), part, parts);
  if (first_pack < end_pack) {
    kernel_.multiply(Packs(), rotated, slot_count_, out, first_pack, end_pack);
  }
  const double* rx = rotated;
  const double* ry = rx + slot_count_;
  const double* rz = ry + slot_count_;
  const auto [first_long, end_long] = PartOf(static_cast<int>(long_rows_.size()), part, parts);
  for (int k = first_long; k < end_long; ++k) {
    // Two partial sums, so that consecutive entries do not wait on each other's adds.
    double a0 = 0, a1 = 0, a2 = 0, b0 = 0, b1 = 0, b2 = 0;
    int p = long_offsets_[k];
    const int end = long_offsets_[k + 1];
    for (; p + 2 <= end; p += 2) {
      const int s = long_columns_[p], t = long_columns_[p + 1];
      const double u = long_values_[p], v = long_values_[p + 1];
      a0 += u * rx[s];
      a1 += u * ry[s];
      a2 += u * rz[s];
      b0 += v * rx[t];
      b1 += v * ry[t];
      b2 += v * rz[t];
    }
    if (p < end) {
      const int s = long_columns_[p];
      a0 += long_values_[p] * rx[s];
      a1 += long_values_[p] * ry[s];
      a2 += long_values_[p] * rz[s];
    }
    double* target = out + 3 * static_cast<std::ptrdiff_t>(long_rows_[k]);
    target[0] = a0 + b0;
    target[1] = a1 + b1;
    target[2] = a2 + b2;
  }
  const auto [first_rigid, end_rigid] = PartOf(static_cast<int>(rigid_rows_.size()), part, parts);
  for (int k = first_rigid; k < end_rigid; ++k) {
    const std::ptrdiff_t at = 3 * static_cast<std::ptrdiff_t>(rigid_rows_[k]);
    Eigen::Map<Eigen::Vector3d>{out + at}.noalias() =
        rotations[rigid_bones_[k]] * Eigen::Map<const Eigen::Vector3d>(rigid_sums + at);
  }
}

std::size_t GeneralRowsPlan::bytes() const {
  const auto ints =
      slot_vertex_.size() + group_slot_offsets_.size() + group_quaternion_offsets_.size() +
      group_weight_offsets_.size() + quaternion_bones_.size() + quaternion_first_.size() +
      pack_entry_offsets_.size() + pack_columns_.size() + pack_rows_.size() + long_rows_.size() +
      long_offsets_.size() + long_columns_.size() + rigid_rows_.size() + rigid_bones_.size();
  const auto doubles = weights_.size() + deltas_.size() + pack_values_.size() + long_values_.size();
  return ints * sizeof(int) + doubles * sizeof(double);
}

}  // namespace deform
