#include "core/model/linear_pose_response.h"

#include <algorithm>
#include <cassert>
#include <utility>

#include "core/model/rotation_blend.h"

namespace deform {
namespace {

// Vertices per block: the block's three coordinate accumulators (6 KB) stay in L1 while every
// response vector streams through once.
constexpr int kBlock = 256;

// Forced inline so the AVX2 entry point below gets its own vector code for the whole evaluation.
#if defined(__GNUC__)
#define DEFORM_ALWAYS_INLINE inline __attribute__((always_inline))
#else
#define DEFORM_ALWAYS_INLINE inline
#endif

// x, y, z[0, count) += (cx, cy, cz) * column[0, count). Vectorised by the compiler.
DEFORM_ALWAYS_INLINE void AddScaledColumn(const double* __restrict column, int count, double cx,
                                          double cy, double cz, double* __restrict x,
                                          double* __restrict y, double* __restrict z) {
  for (int i = 0; i < count; ++i) {
    x[i] += cx * column[i];
    y[i] += cy * column[i];
    z[i] += cz * column[i];
  }
}

using Knot = LinearPoseResponse::Knot;

// x, y, z[0, count) += r * (the three response vectors at u, one column of r each).
DEFORM_ALWAYS_INLINE void AddRotated(const Eigen::Matrix3d& r, const double* u, std::size_t n,
                                     int count, double* x, double* y, double* z) {
  for (int c = 0; c < 3; ++c) {
    AddScaledColumn(u + c * n, count, r(0, c), r(1, c), r(2, c), x, y, z);
  }
}

// The whole evaluation, written once and compiled for AVX2 + FMA and for any x86-64 (or other)
// CPU; Evaluate() picks one at run time.
DEFORM_ALWAYS_INLINE void EvaluateBlocks(int n, const std::vector<int>& bones,
                                         const std::vector<Knot>& knots, const double* columns,
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
      AddRotated(transform.rotation.toRotationMatrix(), u, stride, count, x, y, z);
      const Eigen::Vector3d& t = transform.translation;
      AddScaledColumn(u + 3 * stride, count, t.x(), t.y(), t.z(), x, y, z);
    }
    for (std::size_t k = 0; k < knots.size(); ++k) {
      const Knot& knot = knots[k];
      const Eigen::Quaterniond q =
          PairKnot(transforms[knot.bone_a].rotation, transforms[knot.bone_b].rotation, knot.s);
      AddRotated(q.toRotationMatrix(), knot_columns + 3 * k * stride + begin, stride, count, x, y,
                 z);
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
                                                      const std::vector<Knot>& knots,
                                                      const double* columns,
                                                      const std::vector<RigidTransform>& transforms,
                                                      double* positions) {
  EvaluateBlocks(n, bones, knots, columns, transforms, positions);
}

bool HasAvx2Fma() {
  static const bool has = __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma");
  return has;
}
#endif

}  // namespace

LinearPoseResponse::LinearPoseResponse(int num_vertices, std::vector<int> bones,
                                       std::vector<Knot> knots, std::vector<double> columns)
    : num_vertices_(num_vertices),
      bones_(std::move(bones)),
      knots_(std::move(knots)),
      columns_(std::move(columns)) {
  assert(columns_.size() ==
         (4 * bones_.size() + 3 * knots_.size()) * static_cast<std::size_t>(num_vertices_));
}

void LinearPoseResponse::Evaluate(const std::vector<RigidTransform>& bone_transforms,
                                  double* positions) const {
#if defined(__x86_64__) && defined(__GNUC__)
  if (HasAvx2Fma()) {
    EvaluateAvx2(num_vertices_, bones_, knots_, columns_.data(), bone_transforms, positions);
    return;
  }
#endif
  EvaluateBlocks(num_vertices_, bones_, knots_, columns_.data(), bone_transforms, positions);
}

}  // namespace deform
