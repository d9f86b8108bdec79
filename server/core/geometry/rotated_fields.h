#pragma once

// Posing precomputed responses: a sum of vector fields, each turned by its own rotation. The
// fields are stored by coordinate (three columns of doubles each), so that the sum streams every
// column once and vectorizes across vertices; the result is by rows (x, y, z per vertex), as the
// solver's vectors are.

#include <Eigen/Core>
#include <cstddef>

#if defined(__GNUC__)
#define DEFORM_ALWAYS_INLINE inline __attribute__((always_inline))
#else
#define DEFORM_ALWAYS_INLINE inline
#endif

namespace deform {

// x, y, z[0, count) += (cx, cy, cz) * column[0, count). Inlined into each caller's own
// instruction-set variant and vectorized by the compiler there.
template <typename Value>
DEFORM_ALWAYS_INLINE void AddScaledColumn(const Value* __restrict column, int count, double cx,
                                          double cy, double cz, double* __restrict x,
                                          double* __restrict y, double* __restrict z) {
  for (int i = 0; i < count; ++i) {
    x[i] += cx * column[i];
    y[i] += cy * column[i];
    z[i] += cz * column[i];
  }
}

// x, y, z[0, count) += r * (the field whose c-th coordinate column starts at u + c * stride).
template <typename Value>
DEFORM_ALWAYS_INLINE void AddRotatedField(const Eigen::Matrix3d& r, const Value* u,
                                          std::size_t stride, int count, double* x, double* y,
                                          double* z) {
  for (int c = 0; c < 3; ++c) {
    AddScaledColumn(u + c * stride, count, r(0, c), r(1, c), r(2, c), x, y, z);
  }
}

// out[3 i + a] = sum_k sum_c rotations[k](a, c) * fields[(3 k + c) * stride + i] for i in
// [0, count): field k's c-th coordinate is column 3 k + c, `stride` values apart. out is count
// by 3, by rows, and is overwritten; the sums are in double either way. Fields in float halve
// the bytes streamed, for responses whose rounding does not matter (a direction).
void SumRotatedFields(const double* fields, std::size_t stride, std::size_t count, int num_fields,
                      const Eigen::Matrix3d* rotations, double* out);
void SumRotatedFields(const float* fields, std::size_t stride, std::size_t count, int num_fields,
                      const Eigen::Matrix3d* rotations, double* out);

}  // namespace deform
