// The right-hand side's rows of L'^T r laid out for vector units (the quaternion blend).
//
// A frame's A^T b holds L'^T r, r_j = w_j^2 T_j delta_j, T_j vertex j's quaternion blend (QLERP:
// its bones' unit quaternions weighted, their signs aligned to its first bone's, the blend
// normalized). The rigid rows (rigid_rows.h) are one 3x3 product each. The general rows read the
// rotated deltas of their vertices, which this plan computes kLanes slots at a time and a row's
// entry reads in one load:
//
// - Slots. Every vertex some general row reads has a slot. The slots are grouped by the vertex's
//   ordered bone list (its bone-weight entries' bones, largest weight first), so a group's signed
//   quaternions are the same for all its vertices and a frame blends a group with one set of
//   them. Within a group the slots ascend by vertex. A group is padded to a multiple of
//   kSlotBlock slots with slots of zero delta and zero w^2 that blend the group's first bone alone
//   (their r is 0, never read). Deltas and weights are planar, in slot order; a slot's rotated
//   delta is kRotatedStride doubles (x, y, z, 0), so that a row's entry reads it in one load.
// - Packs. The general rows of at most kMaxPackedEntries entries go in packs of kPackRows rows of
//   the same length, entry by entry (one load takes an entry of each of the pack's rows), their
//   columns as slots. A length's last pack repeats its last row, which then writes the same
//   values twice. Longer rows (a joint node's row reads every vertex of its region) are
//   compressed rows over slots.
// - Anchors. Grouped by their bone lists, rest positions and weights planar in group order.
// - Rigid rows. Grouped by bone and padded to whole blocks, each group's last rows repeating its
//   last row: a frame rotates a group's rigid sums with one matrix.
//
// The same values as blending and rotating vertex by vertex and summing row by row
// (SparseRowTimes3, laplacian_system.h) to round-off: sums in another order, 1e-14 of their norm
// (tested against the normalized blend's full product).
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <vector>

#include "core/geometry/pose.h"
#include "core/model/bone_weights.h"
#include "core/model/laplacian_system.h"
#include "core/model/rigid_rows.h"
#include "core/solver/supernodal_solve.h"

namespace deform {

// The plan's arrays as the kernels read them (internal/general_rows_kernel_impl.h).
struct SlotGroupsView {
  int group_count = 0;
  int slot_count = 0;                 // a multiple of kSlotBlock
  const int* slot_offsets = nullptr;  // group_count + 1, multiples of kSlotBlock
  // group_count + 1: each group's bones' signed quaternions (SignQuaternions' order).
  const int* quaternion_offsets = nullptr;
  const int* weight_offsets = nullptr;  // group_count: weights[offset + k * slots + l], bone k
  const double* weights = nullptr;
  const double* deltas = nullptr;  // 3 planes (x, y, z) of slot_count
};
// The rigid rows grouped by bone: group g's rows rows[offsets[g], offsets[g + 1]) (a multiple of
// kSlotBlock; a group's last rows repeat its last row) are bone bones[g]'s.
struct RigidGroupsView {
  int group_count = 0;
  const int* offsets = nullptr;
  const int* bones = nullptr;
  const int* rows = nullptr;
};
// Rows too long for a pack, compressed over slots: row rows[k]'s entries [offsets[k],
// offsets[k + 1]).
struct LongRowsView {
  const int* rows = nullptr;
  const int* offsets = nullptr;
  const int* columns = nullptr;
  const double* values = nullptr;
};
// The anchors grouped by their bone lists: group g's anchors [offsets[g], offsets[g + 1]) in
// group order, their bones bones[bone_offsets[g], bone_offsets[g + 1]), weights
// weights[weight_offsets[g] + k * count + l] (bone k, anchor l of the group's count), rest
// positions in 3 planes of every anchor (x, y, z) and rows rows[a].
struct AnchorGroupsView {
  int group_count = 0;
  int anchor_count = 0;
  double weight_squared = 0;  // anchor_weight^2
  const int* offsets = nullptr;
  const int* bone_offsets = nullptr;
  const int* bones = nullptr;
  const int* weight_offsets = nullptr;
  const double* weights = nullptr;
  const double* rest = nullptr;
  const int* rows = nullptr;
};
struct RowPacksView {
  // Pack p's entries e in [entry_offsets[p], entry_offsets[p + 1]): kPackRows columns (slots)
  // and values at [kPackRows * e, kPackRows * (e + 1)); its rows at rows[kPackRows * p].
  const int* entry_offsets = nullptr;
  const int* columns = nullptr;
  const double* values = nullptr;
  const int* rows = nullptr;
};

// The kernels of one instruction set (internal/general_rows_kernel_*.cc).
struct GeneralRowsKernel {
  // Blocks [first_block, end_block) of kSlotBlock slots of `frames` (1 to kMaxFramesSideBySide)
  // frames: frame f's rotated delta of slot s (kRotatedStride doubles at kRotatedStride (s frames
  // + f)) = slot_weights * (the group's blend of quaternions[f], 4 doubles x y z w each) * deltas.
  void (*rotate)(const SlotGroupsView& groups, const double* const* quaternions, int frames,
                 const double* slot_weights, double* rotated, int first_block, int end_block);
  // Packs [first_pack, end_pack) of L'^T r of each of `frames` (1 to kMaxFramesSideBySide)
  // frames (`rotated` as `rotate` wrote them) into outs[f] ((n + m) by 3, row-major; written).
  void (*multiply)(const RowPacksView& packs, const double* rotated, int frames,
                   double* const* outs, int first_pack, int end_pack);
  // Long rows [first, end) the same way.
  void (*multiply_long)(const LongRowsView& rows, const double* rotated, int frames,
                        double* const* outs, int first, int end);
  // Blocks [first_block, end_block) of kSlotBlock rigid rows: out's row i = R_bone c_i, R_bone
  // the bone's rotation (`rotations`: 9 doubles each, column-major) and c_i the row's rigid sum
  // (`sums`, (n + m) by 3 row-major).
  void (*multiply_rigid)(const RigidGroupsView& groups, const double* rotations, const double* sums,
                         double* out, int first_block, int end_block);
  // Anchors [first, end) (in group order): out's anchor rows += anchor_weight^2 * the anchor's
  // target, sum_k w_k (R_k rest + t_k) over its bones (`rotations` as above, translations from
  // `bones`).
  void (*add_anchors)(const AnchorGroupsView& anchors, const double* rotations,
                      const RigidTransform* bones, double* out, int first, int end);
};

class GeneralRowsPlan {
 public:
  static constexpr int kSlotBlock = 8;
  static constexpr int kPackRows = 8;
  static constexpr int kMaxPackedEntries = 16;
  // The doubles of a slot's rotated delta: x, y, z and a zero.
  static constexpr int kRotatedStride = 4;

  // The plan of `system`'s L'^T with its rigid rows under the blending `weights`, its kernels
  // those of `kernel` (the baseline's where SolveKernelAvailable says this CPU lacks it).
  static GeneralRowsPlan Build(const LaplacianSystem& system, const RigidRows& rigid,
                               const BoneWeights& weights, SolveKernel kernel = BestSolveKernel());

  int slot_count() const { return slot_count_; }
  // The doubles of a frame's rotated deltas (Rotate's output): kRotatedStride a slot.
  std::size_t rotated_size() const {
    return kRotatedStride * static_cast<std::size_t>(slot_count_);
  }
  // The most frames RotateFrames and MultiplyGeneral take at once.
  static constexpr int kMaxFrames = kMaxSolveColumns / 3;
  // The most frames whose rotated deltas lie side by side; more go in groups of this many, one
  // after the other, so that a pass over the rows reads a group's slots (256 bytes each).
  static constexpr int kMaxFramesSideBySide = 8;
  // The signed quaternions a frame needs (4 doubles each): one per bone of each group.
  int quaternion_count() const { return static_cast<int>(quaternion_bones_.size()); }
  // w_j^2 of each slot's vertex j (0 in the padding), for a factorization's row weights (n).
  std::vector<double> SlotWeights(const Eigen::VectorXd& row_weights_squared) const;
  // quaternions[4 q, 4 q + 4) = x y z w of each group's bones' rotations, each sign aligned to
  // the group's first bone's. No allocation.
  void SignQuaternions(const std::vector<RigidTransform>& bones, double* quaternions) const;

  // Part `part` of `parts` of the frame's rotated deltas (rotated_size() doubles) from
  // SignQuaternions' output and SlotWeights'. Parts are independent.
  void Rotate(const double* quaternions, const double* slot_weights, double* rotated, int part,
              int parts) const;
  // The same for `frames` (1 to kMaxFrames) frames at once, frame f's from quaternions[f], into
  // frames * rotated_size() doubles for MultiplyGeneral: groups of kMaxFramesSideBySide frames
  // one after the other, and within a group each slot's frames side by side.
  void RotateFrames(const double* const* quaternions, int frames, const double* slot_weights,
                    double* rotated, int part, int parts) const;
  // Part `part` of `parts` of the rows of L'^T r into `out` ((n + m) by 3, row-major; written,
  // not added): a rigid row as rotations[bone] * its RigidRowSums entry (`rigid_sums`), a general
  // row from `rotated` (every part's Rotate done). Parts write disjoint rows. No allocation.
  void Multiply(const Eigen::Matrix3d* rotations, const double* rigid_sums, const double* rotated,
                double* out, int part, int parts) const;
  // Multiply's two halves: the general rows of `frames` (1 to kMaxFrames) frames at once from
  // their rotated deltas side by side (RotateFrames'), frame f's into outs[f], each row's
  // entries read once for all of them; and one frame's rigid rows.
  void MultiplyGeneral(const double* rotated, int frames, double* const* outs, int part,
                       int parts) const;
  void MultiplyRigid(const Eigen::Matrix3d* rotations, const double* rigid_sums, double* out,
                     int part, int parts) const;

  // Part `part` of `parts` of the anchors' targets: their rows of `out` += anchor_weight^2 *
  // sum_e w_e (R_e rest + t_e) (`rotations` and `bones` indexed by bone), once every part's
  // Multiply is done. Parts add to disjoint rows. No allocation.
  void AddAnchorTargets(const Eigen::Matrix3d* rotations, const std::vector<RigidTransform>& bones,
                        double* out, int part, int parts) const;

  std::size_t bytes() const;

 private:
  void BuildAnchorGroups(const LaplacianSystem& system);
  SlotGroupsView Groups() const;
  RowPacksView Packs() const;
  RigidGroupsView RigidGroups() const;
  LongRowsView LongRows() const;
  AnchorGroupsView AnchorGroups() const;
  int pack_count() const { return static_cast<int>(pack_entry_offsets_.size()) - 1; }

  GeneralRowsKernel kernel_{};
  int slot_count_ = 0;
  std::vector<int> slot_vertex_;  // per slot, -1 in the padding
  std::vector<int> group_slot_offsets_;
  std::vector<int> group_quaternion_offsets_;
  std::vector<int> group_weight_offsets_;
  std::vector<int> quaternion_bones_;  // per signed quaternion, its bone
  std::vector<int> quaternion_first_;  // per signed quaternion, its group's first bone
  std::vector<double> weights_;
  std::vector<double> deltas_;  // 3 planes
  std::vector<int> pack_entry_offsets_;
  std::vector<int> pack_columns_;
  std::vector<double> pack_values_;
  std::vector<int> pack_rows_;
  // The rows too long for a pack, compressed over slots.
  std::vector<int> long_rows_;
  std::vector<int> long_offsets_;
  std::vector<int> long_columns_;
  std::vector<double> long_values_;
  // The anchors grouped by bone list (AnchorGroupsView).
  double anchor_weight_squared_ = 0;
  std::vector<int> anchor_offsets_;
  std::vector<int> anchor_bone_offsets_;
  std::vector<int> anchor_bones_;
  std::vector<int> anchor_weight_offsets_;
  std::vector<double> anchor_weights_;
  std::vector<double> anchor_rest_;  // 3 planes
  std::vector<int> anchor_rows_;
  // The rigid rows grouped by bone (RigidGroupsView).
  std::vector<int> rigid_offsets_;
  std::vector<int> rigid_bones_;
  std::vector<int> rigid_rows_;
};

}  // namespace deform
