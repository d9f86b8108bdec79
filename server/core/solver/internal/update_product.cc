#include "update_product.h"

#include <Eigen/Core>

#include "core/base/cpu_features.h"

#if defined(__x86_64__) && defined(__GNUC__)
#include <immintrin.h>
#define DEFORM_UPDATE_PRODUCT_AVX2 1
#endif

namespace deform::solver_internal {
namespace {

using RowMatrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

#ifdef DEFORM_UPDATE_PRODUCT_AVX2

__attribute__((target("avx2,fma"))) inline double Sum(__m256d v) {
  const __m128d pair = _mm_add_pd(_mm256_castpd256_pd128(v), _mm256_extractf128_pd(v, 1));
  return _mm_cvtsd_f64(_mm_add_sd(pair, _mm_unpackhi_pd(pair, pair)));
}

// One dot product of two rows: four-wide partial sums, then the tail.
__attribute__((target("avx2,fma"))) double Dot(const double* x, const double* y, int depth) {
  __m256d sum = _mm256_setzero_pd();
  int t = 0;
  for (; t + 4 <= depth; t += 4) {
    sum = _mm256_fmadd_pd(_mm256_loadu_pd(x + t), _mm256_loadu_pd(y + t), sum);
  }
  double s = Sum(sum);
  for (; t < depth; ++t) s += x[t] * y[t];
  return s;
}

// Tiles of two rows of `a` by four rows of `b`: eight four-wide partial sums over the depth (one
// per entry of the tile), each summed at the end, then the tail; the edges entry by entry with
// the same order of sums (Dot).
__attribute__((target("avx2,fma"))) void ProductAvx2(const double* a, std::int64_t m,
                                                     const double* b, int k, int depth, double* c) {
  const int depth4 = depth & ~3;
  std::int64_t r = 0;
  for (; r + 2 <= m; r += 2) {
    const double* a0 = a + r * depth;
    const double* a1 = a0 + depth;
    int col = 0;
    for (; col + 4 <= k; col += 4) {
      const double* b0 = b + static_cast<std::int64_t>(col) * depth;
      const double* b1 = b0 + depth;
      const double* b2 = b1 + depth;
      const double* b3 = b2 + depth;
      __m256d s00 = _mm256_setzero_pd(), s01 = s00, s02 = s00, s03 = s00;
      __m256d s10 = s00, s11 = s00, s12 = s00, s13 = s00;
      for (int t = 0; t < depth4; t += 4) {
        const __m256d x0 = _mm256_loadu_pd(a0 + t), x1 = _mm256_loadu_pd(a1 + t);
        const __m256d y0 = _mm256_loadu_pd(b0 + t), y1 = _mm256_loadu_pd(b1 + t);
        s00 = _mm256_fmadd_pd(x0, y0, s00);
        s10 = _mm256_fmadd_pd(x1, y0, s10);
        s01 = _mm256_fmadd_pd(x0, y1, s01);
        s11 = _mm256_fmadd_pd(x1, y1, s11);
        const __m256d y2 = _mm256_loadu_pd(b2 + t), y3 = _mm256_loadu_pd(b3 + t);
        s02 = _mm256_fmadd_pd(x0, y2, s02);
        s12 = _mm256_fmadd_pd(x1, y2, s12);
        s03 = _mm256_fmadd_pd(x0, y3, s03);
        s13 = _mm256_fmadd_pd(x1, y3, s13);
      }
      double e[2][4] = {{Sum(s00), Sum(s01), Sum(s02), Sum(s03)},
                        {Sum(s10), Sum(s11), Sum(s12), Sum(s13)}};
      for (int t = depth4; t < depth; ++t) {
        for (int j = 0; j < 4; ++j) {
          const double y = b[static_cast<std::int64_t>(col + j) * depth + t];
          e[0][j] += a0[t] * y;
          e[1][j] += a1[t] * y;
        }
      }
      for (int j = 0; j < 4; ++j) {
        c[r * k + col + j] = e[0][j];
        c[(r + 1) * k + col + j] = e[1][j];
      }
    }
    for (; col < k; ++col) {
      const double* bc = b + static_cast<std::int64_t>(col) * depth;
      c[r * k + col] = Dot(a0, bc, depth);
      c[(r + 1) * k + col] = Dot(a1, bc, depth);
    }
  }
  for (; r < m; ++r) {
    for (int col = 0; col < k; ++col) {
      c[r * k + col] = Dot(a + r * depth, b + static_cast<std::int64_t>(col) * depth, depth);
    }
  }
}

#endif

}  // namespace

void UpdateProductPortable(const double* a, std::int64_t m, const double* b, int k, int depth,
                           double* c) {
  using Map = Eigen::Map<const RowMatrix>;
  Eigen::Map<RowMatrix>(c, m, k).noalias() = Map(a, m, depth) * Map(b, k, depth).transpose();
}

bool UpdateProductUsesAvx2() {
#ifdef DEFORM_UPDATE_PRODUCT_AVX2
  return CpuHasAvx2Fma();
#else
  return false;
#endif
}

void UpdateProduct(const double* a, std::int64_t m, const double* b, int k, int depth, double* c) {
#ifdef DEFORM_UPDATE_PRODUCT_AVX2
  if (UpdateProductUsesAvx2()) return ProductAvx2(a, m, b, k, depth, c);
#endif
  UpdateProductPortable(a, m, b, k, depth, c);
}

}  // namespace deform::solver_internal
