// The kernels of general_rows.h, compiled once per instruction set: by
// general_rows_kernel_baseline.cc (two doubles a vector), general_rows_kernel_avx2.cc (-mavx2
// -mfma: four) and general_rows_kernel_avx512.cc (-mavx512f -mavx512vl as well:
// eight, gathers and scatters). Each defines its GeneralRowsKernel from these functions.
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstring>

#if defined(__AVX512F__)
#include <immintrin.h>
#endif

#include "core/base/compile_time_count.h"
#include "core/model/general_rows.h"

#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wpsabi"  // the slot helpers are internal and always inlined

namespace deform {
namespace {

#if defined(__AVX512F__)
constexpr int kLanes = 8;
#elif defined(__AVX2__)
constexpr int kLanes = 4;
#else
constexpr int kLanes = 2;
#endif
static_assert(GeneralRowsPlan::kSlotBlock % kLanes == 0 && GeneralRowsPlan::kPackRows % kLanes == 0,
              "blocks and packs are whole vectors");

using Lanes = double __attribute__((vector_size(8 * kLanes)));

inline Lanes Load(const double* p) {
  Lanes v;
  std::memcpy(&v, p, sizeof v);
  return v;
}
inline Lanes Broadcast(double x) {
  Lanes v;
  for (int l = 0; l < kLanes; ++l) v[l] = x;
  return v;
}

// A slot's rotated delta (x, y, z, 0): kRotatedStride doubles, one AVX register (two SSE2
// registers on the baseline).
static_assert(GeneralRowsPlan::kRotatedStride == 4, "a slot is four doubles");
using Slot = double __attribute__((vector_size(32)));

inline Slot LoadSlot(const double* p) {
  Slot v;
  std::memcpy(&v, p, sizeof v);
  return v;
}
// Where slot `slot`'s rotated deltas begin: `frames` of them side by side, kRotatedStride doubles
// each.
inline const double* SlotFrames(const double* rotated, int slot, int frames) {
  return rotated + GeneralRowsPlan::kRotatedStride * static_cast<std::ptrdiff_t>(slot) * frames;
}
// out's row `row` = (x, y, z) of `sum`.
inline void StoreRow(double* out, int row, Slot sum) {
  double* target = out + 3 * static_cast<std::ptrdiff_t>(row);
  target[0] = sum[0];
  target[1] = sum[1];
  target[2] = sum[2];
}

// base[index[l]] for each lane. With AVX-512 a hardware gather (the masked one: GCC 12's unmasked
// ones read an undefined source register, and -Wmaybe-uninitialized says so); elsewhere one load
// a lane. AVX2's four-lane gather was slower than four loads and inserts on an AMD Zen 3
// (bench/RESULTS.md, "Right-hand side"). (Intel's microcode against Gather Data Sampling, 2023,
// slowed the gathers of its AVX2 processors too; not measured here.)
inline Lanes Gather(const double* base, const int* index) {
#if defined(__AVX512F__)
  return _mm512_mask_i32gather_pd(_mm512_setzero_pd(), 0xff,
                                  _mm256_loadu_si256(reinterpret_cast<const __m256i*>(index)), base,
                                  8);
#else
  Lanes v;
  for (int l = 0; l < kLanes; ++l) v[l] = base[index[l]];
  return v;
#endif
}

// out[3 rows[l] + c] = x, y, z (c = 0, 1, 2) for each lane.
inline void ScatterRows(double* out, const int* rows, Lanes x, Lanes y, Lanes z) {
#if defined(__AVX512F__)
  const __m256i at = _mm256_mullo_epi32(_mm256_loadu_si256(reinterpret_cast<const __m256i*>(rows)),
                                        _mm256_set1_epi32(3));
  _mm512_i32scatter_pd(out, at, x, 8);
  _mm512_i32scatter_pd(out + 1, at, y, 8);
  _mm512_i32scatter_pd(out + 2, at, z, 8);
#else
  for (int l = 0; l < kLanes; ++l) {
    double* row = out + 3 * static_cast<std::ptrdiff_t>(rows[l]);
    row[0] = x[l];
    row[1] = y[l];
    row[2] = z[l];
  }
#endif
}

// out[3 rows[l] + c] += x, y, z (c = 0, 1, 2) for each lane; the rows distinct.
inline void AddToRows(double* out, const int* rows, Lanes x, Lanes y, Lanes z) {
#if defined(__AVX512F__)
  const __m256i at = _mm256_mullo_epi32(_mm256_loadu_si256(reinterpret_cast<const __m256i*>(rows)),
                                        _mm256_set1_epi32(3));
  const __m512d zero = _mm512_setzero_pd();
  _mm512_i32scatter_pd(out, at, x + _mm512_mask_i32gather_pd(zero, 0xff, at, out, 8), 8);
  _mm512_i32scatter_pd(out + 1, at, y + _mm512_mask_i32gather_pd(zero, 0xff, at, out + 1, 8), 8);
  _mm512_i32scatter_pd(out + 2, at, z + _mm512_mask_i32gather_pd(zero, 0xff, at, out + 2, 8), 8);
#else
  for (int l = 0; l < kLanes; ++l) {
    double* row = out + 3 * static_cast<std::ptrdiff_t>(rows[l]);
    row[0] += x[l];
    row[1] += y[l];
    row[2] += z[l];
  }
#endif
}

// The group holding item `index` of groups whose items begin at offsets[0, group_count] (ascending,
// offsets[0] = 0): the last group whose offset is at most `index`.
inline int GroupHolding(const int* offsets, int group_count, int index) {
  return static_cast<int>(std::upper_bound(offsets, offsets + group_count + 1, index) - offsets) -
         1;
}

void RotateSlotsImpl(const SlotGroupsView& groups, const double* const* quaternions, int frames,
                     const double* __restrict slot_weights, double* __restrict rotated,
                     int first_block, int end_block) {
  const int first = first_block * GeneralRowsPlan::kSlotBlock;
  const int end = end_block * GeneralRowsPlan::kSlotBlock;
  const std::ptrdiff_t plane = groups.slot_count;
  const double* dx = groups.deltas;
  const double* dy = dx + plane;
  const double* dz = dy + plane;
  int g = GroupHolding(groups.slot_offsets, groups.group_count, first);
  for (; g < groups.group_count && groups.slot_offsets[g] < end; ++g) {
    const int group_begin = groups.slot_offsets[g];
    const int slots = groups.slot_offsets[g + 1] - group_begin;
    const std::ptrdiff_t group_quaternions = 4 * std::ptrdiff_t{groups.quaternion_offsets[g]};
    const int bones = groups.quaternion_offsets[g + 1] - groups.quaternion_offsets[g];
    const double* w = groups.weights + groups.weight_offsets[g];
    const int stop = std::min(end, groups.slot_offsets[g + 1]);
    for (int s = std::max(first, group_begin); s < stop; s += kLanes) {
      const int l = s - group_begin;
      const Lanes vx = Load(dx + s), vy = Load(dy + s), vz = Load(dz + s);
      const Lanes w2 = Load(slot_weights + s);
      // The frames' slots side by side: every line of these kLanes slots is written here, whole.
      double* target =
          rotated + GeneralRowsPlan::kRotatedStride * static_cast<std::ptrdiff_t>(s) * frames;
      for (int f = 0; f < frames; ++f) {
        const double* q = quaternions[f] + group_quaternions;
        // The blend q = sum_k w_k q_k of this group's signed quaternions.
        Lanes qx = Broadcast(0), qy = qx, qz = qx, qw = qx;
        for (int k = 0; k < bones; ++k) {
          const Lanes wk = Load(w + static_cast<std::ptrdiff_t>(k) * slots + l);
          qx += wk * q[4 * k];
          qy += wk * q[4 * k + 1];
          qz += wk * q[4 * k + 2];
          qw += wk * q[4 * k + 3];
        }
        // v rotated by q / |q|: v + 2 / |q|^2 (w (u x v) + u x (u x v)), u = (qx, qy, qz).
        const Lanes tx = qy * vz - qz * vy, ty = qz * vx - qx * vz, tz = qx * vy - qy * vx;
        const Lanes ux = qy * tz - qz * ty, uy = qz * tx - qx * tz, uz = qx * ty - qy * tx;
        const Lanes scale = 2.0 / (qx * qx + qy * qy + qz * qz + qw * qw);
        const Lanes rx = w2 * (vx + scale * (qw * tx + ux));
        const Lanes ry = w2 * (vy + scale * (qw * ty + uy));
        const Lanes rz = w2 * (vz + scale * (qw * tz + uz));
        for (int lane = 0; lane < kLanes; ++lane) {
          const Slot r = {rx[lane], ry[lane], rz[lane], 0.0};
          std::memcpy(target + GeneralRowsPlan::kRotatedStride * (lane * frames + f), &r, sizeof r);
        }
      }
    }
  }
}

// Calls run(Count<frames>()) for 1 <= frames <= GeneralRowsPlan::kMaxFramesSideBySide.
template <typename Run>
inline void WithFrames(int frames, Run&& run) {
  WithCount<GeneralRowsPlan::kMaxFramesSideBySide>(frames, run);
}

// Packs [first_pack, end_pack) for kFrames frames side by side: kRowsAtOnce rows of a pack at a
// time, so that kRowsAtOnce x kFrames (8 or fewer) sums are in flight and each row's entry (a
// column and a value) is read once for all the frames.
template <int kFrames>
void MultiplyPacksOfFrames(const RowPacksView& packs, const double* __restrict rotated,
                           double* const* outs, int first_pack, int end_pack) {
  constexpr int kRows = GeneralRowsPlan::kPackRows;
  constexpr int kRowsAtOnce = kFrames == 1 ? 8 : kFrames == 2 ? 4 : kFrames <= 4 ? 2 : 1;
  static_assert(kRows % kRowsAtOnce == 0, "a pack is whole groups of rows");
  for (int p = first_pack; p < end_pack; ++p) {
    const int* rows = packs.rows + static_cast<std::ptrdiff_t>(kRows) * p;
    for (int r0 = 0; r0 < kRows; r0 += kRowsAtOnce) {
      Slot sums[kRowsAtOnce][kFrames] = {};
      for (int e = packs.entry_offsets[p]; e < packs.entry_offsets[p + 1]; ++e) {
        const std::ptrdiff_t at = static_cast<std::ptrdiff_t>(kRows) * e + r0;
        for (int r = 0; r < kRowsAtOnce; ++r) {
          const double value = packs.values[at + r];
          const double* slot = SlotFrames(rotated, packs.columns[at + r], kFrames);
          for (int f = 0; f < kFrames; ++f) {
            sums[r][f] += value * LoadSlot(slot + GeneralRowsPlan::kRotatedStride * f);
          }
        }
      }
      for (int r = 0; r < kRowsAtOnce; ++r) {
        for (int f = 0; f < kFrames; ++f) StoreRow(outs[f], rows[r0 + r], sums[r][f]);
      }
    }
  }
}

void MultiplyPacksImpl(const RowPacksView& packs, const double* __restrict rotated, int frames,
                       double* const* outs, int first_pack, int end_pack) {
  WithFrames(frames, [&](auto count) {
    MultiplyPacksOfFrames<decltype(count)::value>(packs, rotated, outs, first_pack, end_pack);
  });
}

// Long rows [first_row, end_row) for kFrames frames side by side, with kChains sums a frame so
// that at least four multiply-adds are independent.
template <int kFrames>
void MultiplyLongRowsOfFrames(const LongRowsView& rows, const double* __restrict rotated,
                              double* const* outs, int first_row, int end_row) {
  constexpr int kChains = kFrames == 1 ? 4 : kFrames == 2 ? 2 : 1;
  for (int k = first_row; k < end_row; ++k) {
    Slot sums[kFrames][kChains] = {};
    int p = rows.offsets[k];
    const int stop = rows.offsets[k + 1];
    for (; p + kChains <= stop; p += kChains) {
      for (int c = 0; c < kChains; ++c) {
        const double* slot = SlotFrames(rotated, rows.columns[p + c], kFrames);
        for (int f = 0; f < kFrames; ++f) {
          sums[f][c] += rows.values[p + c] * LoadSlot(slot + GeneralRowsPlan::kRotatedStride * f);
        }
      }
    }
    for (; p < stop; ++p) {
      const double* slot = SlotFrames(rotated, rows.columns[p], kFrames);
      for (int f = 0; f < kFrames; ++f) {
        sums[f][0] += rows.values[p] * LoadSlot(slot + GeneralRowsPlan::kRotatedStride * f);
      }
    }
    for (int f = 0; f < kFrames; ++f) {
      Slot total = sums[f][0];
      for (int c = 1; c < kChains; ++c) total += sums[f][c];
      StoreRow(outs[f], rows.rows[k], total);
    }
  }
}

void MultiplyLongRowsImpl(const LongRowsView& rows, const double* __restrict rotated, int frames,
                          double* const* outs, int first_row, int end_row) {
  WithFrames(frames, [&](auto count) {
    MultiplyLongRowsOfFrames<decltype(count)::value>(rows, rotated, outs, first_row, end_row);
  });
}

void MultiplyRigidRowsImpl(const RigidGroupsView& groups, const double* rotations,
                           const double* __restrict sums, double* __restrict out, int first_block,
                           int end_block) {
  const int first = first_block * GeneralRowsPlan::kSlotBlock;
  const int end = end_block * GeneralRowsPlan::kSlotBlock;
  int g = GroupHolding(groups.offsets, groups.group_count, first);
  for (; g < groups.group_count && groups.offsets[g] < end; ++g) {
    const double* r = rotations + 9 * static_cast<std::ptrdiff_t>(groups.bones[g]);  // by column
    const int stop = std::min(end, groups.offsets[g + 1]);
    for (int k = std::max(first, groups.offsets[g]); k < stop; k += kLanes) {
      const int* rows = groups.rows + k;
      int at[kLanes];
      for (int l = 0; l < kLanes; ++l) at[l] = 3 * rows[l];
      const Lanes cx = Gather(sums, at), cy = Gather(sums + 1, at), cz = Gather(sums + 2, at);
      ScatterRows(out, rows, r[0] * cx + r[3] * cy + r[6] * cz, r[1] * cx + r[4] * cy + r[7] * cz,
                  r[2] * cx + r[5] * cy + r[8] * cz);
    }
  }
}

void AddAnchorsImpl(const AnchorGroupsView& anchors, const double* rotations,
                    const RigidTransform* bones, double* __restrict out, int first, int end) {
  const std::ptrdiff_t plane = anchors.anchor_count;
  const double* px = anchors.rest;
  const double* py = px + plane;
  const double* pz = py + plane;
  const double scale = anchors.weight_squared;
  int g = GroupHolding(anchors.offsets, anchors.group_count, first);
  for (; g < anchors.group_count && anchors.offsets[g] < end; ++g) {
    const int begin = anchors.offsets[g];
    const int count = anchors.offsets[g + 1] - begin;
    const int* group_bones = anchors.bones + anchors.bone_offsets[g];
    const int bone_count = anchors.bone_offsets[g + 1] - anchors.bone_offsets[g];
    const double* w = anchors.weights + anchors.weight_offsets[g];
    const int stop = std::min(end, anchors.offsets[g + 1]);
    int a = std::max(first, begin);
    // Whole vectors, then the group's last anchors one at a time (no padding: rows are added to).
    for (; a + kLanes <= stop; a += kLanes) {
      const Lanes x = Load(px + a), y = Load(py + a), z = Load(pz + a);
      Lanes tx = Broadcast(0), ty = tx, tz = tx;
      for (int k = 0; k < bone_count; ++k) {
        const double* r = rotations + 9 * static_cast<std::ptrdiff_t>(group_bones[k]);
        const Eigen::Vector3d& t = bones[group_bones[k]].translation;
        const Lanes wk = Load(w + static_cast<std::ptrdiff_t>(k) * count + (a - begin));
        tx += wk * (r[0] * x + r[3] * y + r[6] * z + t.x());
        ty += wk * (r[1] * x + r[4] * y + r[7] * z + t.y());
        tz += wk * (r[2] * x + r[5] * y + r[8] * z + t.z());
      }
      AddToRows(out, anchors.rows + a, scale * tx, scale * ty, scale * tz);
    }
    for (; a < stop; ++a) {
      double target[3] = {0, 0, 0};
      for (int k = 0; k < bone_count; ++k) {
        const double* r = rotations + 9 * static_cast<std::ptrdiff_t>(group_bones[k]);
        const Eigen::Vector3d& t = bones[group_bones[k]].translation;
        const double wk = w[static_cast<std::ptrdiff_t>(k) * count + (a - begin)];
        for (int c = 0; c < 3; ++c) {
          target[c] += wk * (r[c] * px[a] + r[3 + c] * py[a] + r[6 + c] * pz[a] + t[c]);
        }
      }
      double* row = out + 3 * static_cast<std::ptrdiff_t>(anchors.rows[a]);
      for (int c = 0; c < 3; ++c) row[c] += scale * target[c];
    }
  }
}

}  // namespace
}  // namespace deform

#pragma GCC diagnostic pop
