#include "core/geometry/rotated_fields.h"

#include <algorithm>

#include "core/base/cpu_features.h"

namespace deform {
namespace {

// Vertices per block: the three accumulators (6 KB) stay in L1 while the columns stream through.
constexpr int kBlock = 256;

template <typename Value>
DEFORM_ALWAYS_INLINE void SumBlocks(const Value* fields, std::size_t stride, std::size_t count,
                                    int num_fields, const Eigen::Matrix3d* rotations, double* out) {
  alignas(64) double x[kBlock];
  alignas(64) double y[kBlock];
  alignas(64) double z[kBlock];
  for (std::size_t begin = 0; begin < count; begin += kBlock) {
    const int block = static_cast<int>(std::min<std::size_t>(kBlock, count - begin));
    std::fill_n(x, block, 0.0);
    std::fill_n(y, block, 0.0);
    std::fill_n(z, block, 0.0);
    for (int k = 0; k < num_fields; ++k) {
      AddRotatedField(rotations[k], fields + 3 * static_cast<std::size_t>(k) * stride + begin,
                      stride, block, x, y, z);
    }
    double* o = out + 3 * begin;
    for (int i = 0; i < block; ++i) {
      o[3 * i] = x[i];
      o[3 * i + 1] = y[i];
      o[3 * i + 2] = z[i];
    }
  }
}

#if defined(__x86_64__) && defined(__GNUC__)
template <typename Value>
__attribute__((target("avx2,fma"))) void SumBlocksAvx2(const Value* fields, std::size_t stride,
                                                       std::size_t count, int num_fields,
                                                       const Eigen::Matrix3d* rotations,
                                                       double* out) {
  SumBlocks(fields, stride, count, num_fields, rotations, out);
}
#endif

template <typename Value>
void SumRotated(const Value* fields, std::size_t stride, std::size_t count, int num_fields,
                const Eigen::Matrix3d* rotations, double* out) {
#if defined(__x86_64__) && defined(__GNUC__)
  if (CpuHasAvx2Fma()) {
    SumBlocksAvx2(fields, stride, count, num_fields, rotations, out);
    return;
  }
#endif
  SumBlocks(fields, stride, count, num_fields, rotations, out);
}

}  // namespace

void SumRotatedFields(const double* fields, std::size_t stride, std::size_t count, int num_fields,
                      const Eigen::Matrix3d* rotations, double* out) {
  SumRotated(fields, stride, count, num_fields, rotations, out);
}

void SumRotatedFields(const float* fields, std::size_t stride, std::size_t count, int num_fields,
                      const Eigen::Matrix3d* rotations, double* out) {
  SumRotated(fields, stride, count, num_fields, rotations, out);
}

}  // namespace deform
