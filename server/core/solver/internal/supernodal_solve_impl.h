// The supernodal triangular passes, written once and compiled once per instruction set: included
// by supernodal_solve_baseline.cc and supernodal_solve_avx2.cc (built with -mavx2 -mfma), each of
// which exports a table of these passes (SolveKernelFunctions) under its own name. Include it in
// exactly one place per variant.
//
// Everything here is in an anonymous namespace and no library header is included, so the variants
// never meet at link time: an inline function with external linkage compiled with AVX2 could
// otherwise become the copy the linker keeps for the whole program, and fault on an older CPU.
//
// A supernode's own unknowns are kept planar (all x, then y, then z) in a small buffer while its
// block is applied, so every inner loop is a dot product or an axpy along a contiguous row of the
// block. In the forward pass rows go four at a time, so each load of the unknowns serves four rows
// and the sums run as twelve independent chains (the backward pass: strips of columns, see
// BackwardUpdate); the loops over a row are written with four-wide vectors (one AVX
// register, or two SSE2 registers on the baseline).
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <utility>

#include "core/base/compile_time_count.h"
#include "core/solver/supernodal_solve.h"

#if defined(__AVX__)
#include <immintrin.h>  // its intrinsics are always inlined: nothing of it reaches the linker
#endif

#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wpsabi"  // the vector helpers are internal and always inlined

namespace deform {
namespace {

#if defined(__AVX__)
// Four doubles: one AVX register.
typedef double Vec4 __attribute__((vector_size(32)));
typedef double Vec4Unaligned __attribute__((vector_size(32), aligned(8), may_alias));

inline Vec4 Load4(const double* p) { return *reinterpret_cast<const Vec4Unaligned*>(p); }
inline void Store4(double* p, Vec4 v) { *reinterpret_cast<Vec4Unaligned*>(p) = v; }
inline Vec4 MakeVec4(double a, double b, double c, double d) { return Vec4{a, b, c, d}; }
inline double Lane(Vec4 v, int i) { return v[i]; }
inline double Sum4(Vec4 v) { return (v[0] + v[2]) + (v[1] + v[3]); }
// Four floats of a float32 factor, widened to doubles: one conversion from memory. (GCC 12 makes
// __builtin_convertvector of four floats into a load, a shuffle, two half-width conversions and an
// insert: five instructions on every value block of a float32 factor's three-column passes.)
inline Vec4 Load4(const float* p) { return (Vec4)_mm256_cvtps_pd(_mm_loadu_ps(p)); }

// (sum of a, sum of b, sum of c, sum of d) in two rounds of shuffles and adds.
inline Vec4 Sum4x4(Vec4 a, Vec4 b, Vec4 c, Vec4 d) {
#if defined(__clang__)
  const Vec4 ab =
      __builtin_shufflevector(a, b, 0, 4, 2, 6) + __builtin_shufflevector(a, b, 1, 5, 3, 7);
  const Vec4 cd =
      __builtin_shufflevector(c, d, 0, 4, 2, 6) + __builtin_shufflevector(c, d, 1, 5, 3, 7);
  return __builtin_shufflevector(ab, cd, 0, 1, 4, 5) + __builtin_shufflevector(ab, cd, 2, 3, 6, 7);
#else
  typedef long long Index4 __attribute__((vector_size(32)));
  const Vec4 ab =
      __builtin_shuffle(a, b, Index4{0, 4, 2, 6}) + __builtin_shuffle(a, b, Index4{1, 5, 3, 7});
  const Vec4 cd =
      __builtin_shuffle(c, d, Index4{0, 4, 2, 6}) + __builtin_shuffle(c, d, Index4{1, 5, 3, 7});
  return __builtin_shuffle(ab, cd, Index4{0, 1, 4, 5}) +
         __builtin_shuffle(ab, cd, Index4{2, 3, 6, 7});
#endif
}
#else
// Four doubles without AVX: two SSE2 registers (a 32-byte vector type would be emulated through
// memory).
typedef double Vec2 __attribute__((vector_size(16)));
typedef double Vec2Unaligned __attribute__((vector_size(16), aligned(8), may_alias));

struct Vec4 {
  Vec2 lo, hi;
};

inline Vec4 operator+(Vec4 a, Vec4 b) { return Vec4{a.lo + b.lo, a.hi + b.hi}; }
inline Vec4 operator-(Vec4 a, Vec4 b) { return Vec4{a.lo - b.lo, a.hi - b.hi}; }
inline Vec4 operator*(Vec4 a, Vec4 b) { return Vec4{a.lo * b.lo, a.hi * b.hi}; }
inline Vec4 operator/(Vec4 a, Vec4 b) { return Vec4{a.lo / b.lo, a.hi / b.hi}; }
inline Vec4& operator+=(Vec4& a, Vec4 b) { return a = a + b; }
inline Vec4& operator-=(Vec4& a, Vec4 b) { return a = a - b; }

inline Vec4 Load4(const double* p) {
  return Vec4{*reinterpret_cast<const Vec2Unaligned*>(p),
              *reinterpret_cast<const Vec2Unaligned*>(p + 2)};
}
inline void Store4(double* p, Vec4 v) {
  *reinterpret_cast<Vec2Unaligned*>(p) = v.lo;
  *reinterpret_cast<Vec2Unaligned*>(p + 2) = v.hi;
}
inline Vec4 MakeVec4(double a, double b, double c, double d) {
  return Vec4{Vec2{a, b}, Vec2{c, d}};
}
inline double Lane(Vec4 v, int i) { return i < 2 ? v.lo[i] : v.hi[i - 2]; }
// Four floats of a float32 factor, widened to doubles.
inline Vec4 Load4(const float* p) { return MakeVec4(p[0], p[1], p[2], p[3]); }
inline double Sum4(Vec4 v) {
  const Vec2 s = v.lo + v.hi;
  return s[0] + s[1];
}
inline Vec4 Sum4x4(Vec4 a, Vec4 b, Vec4 c, Vec4 d) {
  return MakeVec4(Sum4(a), Sum4(b), Sum4(c), Sum4(d));
}
#endif

inline Vec4 Splat4(double v) { return MakeVec4(v, v, v, v); }

// The three planar columns of a supernode's unknowns (or right-hand side), `width` long each.
struct Planar {
  double* x;
  double* y;
  double* z;
};

inline int RoundUp4(int n) { return (n + 3) & ~3; }

// Each column is padded to a multiple of four, so the loops over a whole row need no scalar tail:
// the padding is zero while it multiplies rows (ZeroPadding), and a row read past its end reads
// the next row or the zeros that follow the factor's values, times zero.
inline Planar PlanarOf(double* buffer, int width) {
  const int stride = RoundUp4(width);
  return Planar{buffer, buffer + stride, buffer + 2 * stride};
}

inline void ZeroPadding(const Planar& p, int width) {
  for (int k = width; k < RoundUp4(width); ++k) p.x[k] = p.y[k] = p.z[k] = 0;
}

// (*sx, *sy, *sz) += r * (x, y, z).
inline void MultiplyAdd3(Vec4 r, Vec4 x, Vec4 y, Vec4 z, Vec4* sx, Vec4* sy, Vec4* sz) {
  *sx += r * x;
  *sy += r * y;
  *sz += r * z;
}

// sums[4 j + c] = sum over k < n of row_j[k] * p.c[k], for the four rows j and the columns c
// (sums[4 j + 3] = 0: the layout of four solution rows). `n` is a multiple of four: the callers
// pass a tile's start column or a padded width.
template <typename Value>
inline void Dot4x3(const Value* __restrict r0, const Value* __restrict r1,
                   const Value* __restrict r2, const Value* __restrict r3, const Planar& p, int n,
                   double* __restrict sums) {
  const double* __restrict px = p.x;
  const double* __restrict py = p.y;
  const double* __restrict pz = p.z;
  Vec4 a0 = Splat4(0), a1 = a0, a2 = a0, b0 = a0, b1 = a0, b2 = a0;
  Vec4 c0 = a0, c1 = a0, c2 = a0, d0 = a0, d1 = a0, d2 = a0;
  for (int k = 0; k < n; k += 4) {
    const Vec4 x = Load4(px + k), y = Load4(py + k), z = Load4(pz + k);
    MultiplyAdd3(Load4(r0 + k), x, y, z, &a0, &a1, &a2);
    MultiplyAdd3(Load4(r1 + k), x, y, z, &b0, &b1, &b2);
    MultiplyAdd3(Load4(r2 + k), x, y, z, &c0, &c1, &c2);
    MultiplyAdd3(Load4(r3 + k), x, y, z, &d0, &d1, &d2);
  }
  const Vec4 zero = Splat4(0);
  Store4(sums, Sum4x4(a0, a1, a2, zero));
  Store4(sums + 4, Sum4x4(b0, b1, b2, zero));
  Store4(sums + 8, Sum4x4(c0, c1, c2, zero));
  Store4(sums + 12, Sum4x4(d0, d1, d2, zero));
}

// sums[c] = sum over k < n of row[k] * p.c[k].
template <typename Value>
inline void Dot1x3(const Value* __restrict row, const Planar& p, int n, double* __restrict sums) {
  Vec4 a0 = Splat4(0), a1 = a0, a2 = a0;
  int k = 0;
  for (; k + 4 <= n; k += 4) {
    const Vec4 r = Load4(row + k);
    a0 += r * Load4(p.x + k);
    a1 += r * Load4(p.y + k);
    a2 += r * Load4(p.z + k);
  }
  double s0 = Sum4(a0), s1 = Sum4(a1), s2 = Sum4(a2);
  for (; k < n; ++k) {
    s0 += row[k] * p.x[k];
    s1 += row[k] * p.y[k];
    s2 += row[k] * p.z[k];
  }
  sums[0] = s0;
  sums[1] = s1;
  sums[2] = s2;
}

// p.c[k] -= sum over the four rows j of row_j[k] * coefficients[3 j + c], for k < n.
template <typename Value>
inline void SubtractRows4x3(const Value* __restrict r0, const Value* __restrict r1,
                            const Value* __restrict r2, const Value* __restrict r3,
                            const double* __restrict coefficients, const Planar& p, int n) {
  double* __restrict px = p.x;
  double* __restrict py = p.y;
  double* __restrict pz = p.z;
  const double* q = coefficients;
  int k = 0;
  {
    const Vec4 a0 = Splat4(q[0]), a1 = Splat4(q[1]), a2 = Splat4(q[2]);
    const Vec4 b0 = Splat4(q[3]), b1 = Splat4(q[4]), b2 = Splat4(q[5]);
    const Vec4 c0 = Splat4(q[6]), c1 = Splat4(q[7]), c2 = Splat4(q[8]);
    const Vec4 d0 = Splat4(q[9]), d1 = Splat4(q[10]), d2 = Splat4(q[11]);
    for (; k + 4 <= n; k += 4) {
      const Vec4 w0 = Load4(r0 + k), w1 = Load4(r1 + k), w2 = Load4(r2 + k), w3 = Load4(r3 + k);
      Store4(px + k, Load4(px + k) - (w0 * a0 + w1 * b0 + w2 * c0 + w3 * d0));
      Store4(py + k, Load4(py + k) - (w0 * a1 + w1 * b1 + w2 * c1 + w3 * d1));
      Store4(pz + k, Load4(pz + k) - (w0 * a2 + w1 * b2 + w2 * c2 + w3 * d2));
    }
  }
  for (; k < n; ++k) {
    px[k] -= r0[k] * q[0] + r1[k] * q[3] + r2[k] * q[6] + r3[k] * q[9];
    py[k] -= r0[k] * q[1] + r1[k] * q[4] + r2[k] * q[7] + r3[k] * q[10];
    pz[k] -= r0[k] * q[2] + r1[k] * q[5] + r2[k] * q[8] + r3[k] * q[11];
  }
}

// p.c[k] -= row[k] * coefficients[c], for k < n.
template <typename Value>
inline void SubtractRow1x3(const Value* __restrict row, const double* __restrict coefficients,
                           const Planar& p, int n) {
  const double q0 = coefficients[0], q1 = coefficients[1], q2 = coefficients[2];
  int k = 0;
  {
    const Vec4 a0 = Splat4(q0), a1 = Splat4(q1), a2 = Splat4(q2);
    for (; k + 4 <= n; k += 4) {
      const Vec4 w = Load4(row + k);
      Store4(p.x + k, Load4(p.x + k) - w * a0);
      Store4(p.y + k, Load4(p.y + k) - w * a1);
      Store4(p.z + k, Load4(p.z + k) - w * a2);
    }
  }
  for (; k < n; ++k) {
    p.x[k] -= row[k] * q0;
    p.y[k] -= row[k] * q1;
    p.z[k] -= row[k] * q2;
  }
}

// The factor's values are read as one stream: ascending in the forward pass, supernode after
// supernode, and descending supernode by supernode in the backward pass. Each pass asks for the
// bytes it will read kPrefetchBytes later (ahead in the forward pass, below in the backward pass)
// as it reads the ones in hand (the three-column backward pass in its own way: see kStripVecs), so
// that a factor larger than the cache arrives while the kernel computes instead of after it:
// without it a solve bound by memory takes about the sum of its arithmetic and of reading its
// factor, not the larger of the two. Into the outer caches (prefetcht2), except the three-column
// forward pass's on AMD processors (below). The distance and the hint were chosen by measurement
// (deform_bench's TriangularSolve and BatchedSolve on the arm; nearby distances measured alike:
// bench/RESULTS.md, "Triangular solve kernels").
//
// The hint. Non-temporal (prefetchnta) only for the three-column forward pass, and only on AMD
// processors (ForwardStreamIsNonTemporal): AMD's last-level cache is filled by what a core's L2
// evicts, and a line fetched non-temporally is not put there, so the forward pass's stream
// neither spends that traffic nor evicts the lines of the factor that the backward pass left
// there. Elsewhere the hint measured slower (both passes on a Xeon, the backward and the batched
// passes on AMD), so they keep prefetcht2, as do other vendors' processors, where this pass has
// not been measured alone. The figures: bench/RESULTS.md, "Triangular solve kernels".
constexpr std::ptrdiff_t kPrefetchBytes = 16384;
// A factor that fits a core's own cache (its L2) is not prefetched: it stays there between
// solves, and the prefetches only cost issue slots (the smallest shared mesh measured slower with
// them). A larger one is, although it may fit the shared last-level cache: whether it is still
// there at the next frame depends on what else ran in between (the service's other work, a shared
// machine's neighbours). Cold solves (deform_bench's ColdSolve) gain from the prefetch, and
// cache-resident ones lose nothing: bench/RESULTS.md, "Triangular solve kernels".
constexpr std::int64_t kPrefetchMinFactorBytes = std::int64_t{4} << 20;

template <typename Value>
inline bool StreamsFromMemory(const SupernodalFactorView& f) {
  return f.value_pointers[f.num_supernodes] * static_cast<std::int64_t>(sizeof(Value)) >
         kPrefetchMinFactorBytes;
}

// Supernode sn's block of the factor (see SupernodalFactorView).
template <typename Value>
struct SupernodeBlock {
  int first;              // its first column
  int width;              // its number of columns
  const int* rows;        // its row indices
  std::int64_t num_rows;  // their number
  const Value* values;    // its dense row-major (num_rows) x (width) block
  bool prefetch;          // the factor is streamed from memory (StreamsFromMemory)
};

// ForwardStreamIsNonTemporal(), read once (see kPrefetchBytes).
const bool kForwardStreamIsNonTemporal = ForwardStreamIsNonTemporal();

// The factor's values as stored: double, or float32 (widened to double as they are read).
template <typename Value>
inline const Value* ValuesOf(const SupernodalFactorView& f);
template <>
inline const double* ValuesOf<double>(const SupernodalFactorView& f) {
  return f.values;
}
template <>
inline const float* ValuesOf<float>(const SupernodalFactorView& f) {
  return f.float_values;
}

template <typename Value>
inline SupernodeBlock<Value> BlockOf(const SupernodalFactorView& f, int sn) {
  const int first = f.supernode_columns[sn];
  return SupernodeBlock<Value>{first,
                               f.supernode_columns[sn + 1] - first,
                               f.row_indices + f.row_pointers[sn],
                               f.row_pointers[sn + 1] - f.row_pointers[sn],
                               ValuesOf<Value>(f) + f.value_pointers[sn],
                               StreamsFromMemory<Value>(f)};
}

// How a prefetch asks for a line: into the outer caches (prefetcht2), or into the nearest cache
// without being put into the outer ones when it leaves (prefetchnta; see kPrefetchBytes).
enum class Hint { kOuterCaches, kNonTemporal };

// Asks for the cache line at `address` with `kHint`. Inline assembly on x86: GCC 12's mod/ref
// analysis counts __builtin_prefetch as no side effect, and deleted every call of PrefetchFactor as
// a function that does nothing (none were left in the objects; with -fno-ipa-modref they stay).
template <Hint kHint = Hint::kOuterCaches>
inline void PrefetchLine(std::uintptr_t address) {
#if defined(__x86_64__) || defined(__i386__)
  if constexpr (kHint == Hint::kNonTemporal) {
    asm volatile("prefetchnta %0" : : "m"(*reinterpret_cast<const char*>(address)));
  } else {
    asm volatile("prefetcht2 %0" : : "m"(*reinterpret_cast<const char*>(address)));
  }
#else
  __builtin_prefetch(reinterpret_cast<const void*>(address), 0,
                     kHint == Hint::kNonTemporal ? 0 : 1);
#endif
}

enum class Pass { kForward, kBackward };

// The factor's lines at distance kPrefetchBytes from [values, values + count) of `s`'s block in
// `pass`'s direction (none when its factor does not stream from memory), asked for all at once
// (PrefetchFactor) or one at a time through a loop: Step(k) asks for the k-th line, Rest(steps)
// for those the loop's `steps` steps left. A prefetch never faults: addresses beyond the
// factor's ends are harmless (computed as integers, since a pointer may not leave its array).
//
// The batched passes spread theirs (a line per step of a block's loop, which reads about a line a
// step; in the backward pass a line per row of each strip of columns): asked all at the start of
// a block, they held up the loads behind them. The three-column passes keep the burst: spread
// among their few loads a step, they measured slower (bench/RESULTS.md, "Batched solves" and
// "Triangular solve kernels").
struct SpreadPrefetch {
  std::uintptr_t begin = 0;
  std::ptrdiff_t lines = 0;
  template <Pass kPass, typename Value>
  static SpreadPrefetch Of(const SupernodeBlock<Value>& s, const Value* values,
                           std::ptrdiff_t count) {
    if (!s.prefetch) return {};
    const std::uintptr_t at = reinterpret_cast<std::uintptr_t>(values);
    return {kPass == Pass::kForward ? at + kPrefetchBytes : at - kPrefetchBytes,
            (count * static_cast<std::ptrdiff_t>(sizeof(Value)) + 63) / 64};
  }
  void Step(std::ptrdiff_t k) const {
    if (k < lines) PrefetchLine(begin + 64 * static_cast<std::uintptr_t>(k));
  }
  template <Hint kHint = Hint::kOuterCaches>
  void Rest(std::ptrdiff_t steps) const {
    for (std::ptrdiff_t k = steps; k < lines; ++k) {
      PrefetchLine<kHint>(begin + 64 * static_cast<std::uintptr_t>(k));
    }
  }
};

// All of SpreadPrefetch's lines at once: the three-column passes' prefetch, non-temporal in the
// forward pass where kForwardStreamIsNonTemporal.
template <Pass kPass, typename Value>
inline void PrefetchFactor(const SupernodeBlock<Value>& s, const Value* values,
                           std::ptrdiff_t count) {
  const SpreadPrefetch lines = SpreadPrefetch::Of<kPass>(s, values, count);
  if (kPass == Pass::kForward && kForwardStreamIsNonTemporal) {
    lines.Rest<Hint::kNonTemporal>(0);
  } else {
    lines.Rest(0);
  }
}

// The solution rows during the solve (supernodal_solve.h).
constexpr int kRowStride = kSolveRowStride;

// The first `doubles`-double boundary in `work` (whose size leaves that much slack).
inline double* AlignedTo(double* work, int doubles) {
  const std::uintptr_t bytes = doubles * sizeof(double);
  const std::uintptr_t misalignment = reinterpret_cast<std::uintptr_t>(work) % bytes;
  return work + (misalignment ? (bytes - misalignment) / sizeof(double) : 0);
}

inline double* Row(double* y, int row) { return y + kRowStride * static_cast<std::ptrdiff_t>(row); }
inline const double* Row(const double* y, int row) {
  return y + kRowStride * static_cast<std::ptrdiff_t>(row);
}

// Forward substitution with `supernode`'s dense lower-triangular diagonal block (row-major,
// width square): solves for its unknowns, whose right-hand sides are the solution rows from
// `ys` on, writing them back there and planar into `p`.
template <typename Value>
inline void ForwardDiagonal(const SupernodeBlock<Value>& supernode, double* __restrict ys,
                            const Planar& p) {
  const Value* __restrict block = supernode.values;
  const int width = supernode.width;
  int c = 0;
  for (; c + 4 <= width; c += 4) {
    const Value* r0 = block + static_cast<std::ptrdiff_t>(c) * width;
    const Value* r1 = r0 + width;
    const Value* r2 = r1 + width;
    const Value* r3 = r2 + width;
    PrefetchFactor<Pass::kForward>(supernode, r0, 4 * width);
    double s[16];
    Dot4x3(r0, r1, r2, r3, p, c, s);
    const double* t = Row(ys, c);
    for (int i = 0; i < 16; ++i) s[i] = t[i] - s[i];
    // The 4 by 4 triangle at the tile's corner, one column (x, y, z) at a time. The pivots'
    // inverses depend on the factor alone, so their divisions stay off the chain of unknowns.
    const double i0 = 1.0 / r0[c], i1 = 1.0 / r1[c + 1], i2 = 1.0 / r2[c + 2], i3 = 1.0 / r3[c + 3];
    double* out[3] = {p.x + c, p.y + c, p.z + c};
    for (int d = 0; d < 3; ++d) {
      const double u0 = s[d] * i0;
      const double u1 = (s[4 + d] - r1[c] * u0) * i1;
      const double u2 = (s[8 + d] - r2[c] * u0 - r2[c + 1] * u1) * i2;
      const double u3 = (s[12 + d] - r3[c] * u0 - r3[c + 1] * u1 - r3[c + 2] * u2) * i3;
      out[d][0] = u0;
      out[d][1] = u1;
      out[d][2] = u2;
      out[d][3] = u3;
    }
  }
  for (; c < width; ++c) {
    const Value* row = block + static_cast<std::ptrdiff_t>(c) * width;
    PrefetchFactor<Pass::kForward>(supernode, row, width);
    double s[3];
    Dot1x3(row, p, c, s);
    const double* t = Row(ys, c);
    const double inverse = 1.0 / row[c];
    p.x[c] = (t[0] - s[0]) * inverse;
    p.y[c] = (t[1] - s[1]) * inverse;
    p.z[c] = (t[2] - s[2]) * inverse;
  }
  for (int k = 0; k < width; ++k) {
    double* t = Row(ys, k);
    t[0] = p.x[k];
    t[1] = p.y[k];
    t[2] = p.z[k];
  }
}

// Back substitution with the transpose of the diagonal block: `p` holds the right-hand side on
// entry (and is consumed); the solution goes to the solution rows from `ys` on. Rows of the block
// are taken four at a time from the bottom: their corner triangle is solved, then they update the
// rows above together.
template <typename Value>
inline void BackwardDiagonal(const SupernodeBlock<Value>& supernode, double* __restrict ys,
                             const Planar& p) {
  const Value* __restrict block = supernode.values;
  const int width = supernode.width;
  int c = width;  // rows [0, c) are still to solve
  for (; c >= 4; c -= 4) {
    const int f = c - 4;
    const Value* r0 = block + static_cast<std::ptrdiff_t>(f) * width;
    const Value* r1 = r0 + width;
    const Value* r2 = r1 + width;
    const Value* r3 = r2 + width;
    PrefetchFactor<Pass::kBackward>(supernode, r0, 4 * width);
    double* in[3] = {p.x + f, p.y + f, p.z + f};
    double solved[12];  // solved[3 j + d]: unknown f + j, column d
    const double i0 = 1.0 / r0[f], i1 = 1.0 / r1[f + 1], i2 = 1.0 / r2[f + 2], i3 = 1.0 / r3[f + 3];
    for (int d = 0; d < 3; ++d) {
      const double* v = in[d];
      const double u3 = v[3] * i3;
      const double u2 = (v[2] - r3[f + 2] * u3) * i2;
      const double u1 = (v[1] - r3[f + 1] * u3 - r2[f + 1] * u2) * i1;
      const double u0 = (v[0] - r3[f] * u3 - r2[f] * u2 - r1[f] * u1) * i0;
      solved[d] = u0;
      solved[3 + d] = u1;
      solved[6 + d] = u2;
      solved[9 + d] = u3;
    }
    for (int j = 0; j < 4; ++j) {
      double* t = Row(ys, f + j);
      t[0] = solved[3 * j];
      t[1] = solved[3 * j + 1];
      t[2] = solved[3 * j + 2];
    }
    SubtractRows4x3(r0, r1, r2, r3, solved, p, f);
  }
  for (; c > 0; --c) {
    const int f = c - 1;
    const Value* row = block + static_cast<std::ptrdiff_t>(f) * width;
    PrefetchFactor<Pass::kBackward>(supernode, row, width);
    const double inverse = 1.0 / row[f];
    const double solved[3] = {p.x[f] * inverse, p.y[f] * inverse, p.z[f] * inverse};
    double* t = Row(ys, f);
    t[0] = solved[0];
    t[1] = solved[1];
    t[2] = solved[2];
    SubtractRow1x3(row, solved, p, f);
  }
}

// y[rows[r]] -= (block row r) . p for `supernode`'s rows below its diagonal block (r >= width).
template <typename Value>
inline void ForwardUpdate(const SupernodeBlock<Value>& supernode, const Planar& p,
                          double* __restrict y) {
  const Value* __restrict block = supernode.values;
  const int* __restrict rows = supernode.rows;
  const int width = supernode.width;
  const std::int64_t num_rows = supernode.num_rows;
  ZeroPadding(p, width);
  const int padded = RoundUp4(width);
  std::int64_t r = width;
  for (; r + 4 <= num_rows; r += 4) {
    const Value* r0 = block + r * width;
    PrefetchFactor<Pass::kForward>(supernode, r0, 4 * width);
    double s[16];
    Dot4x3(r0, r0 + width, r0 + 2 * width, r0 + 3 * width, p, padded, s);
    for (int j = 0; j < 4; ++j) {
      double* t = Row(y, rows[r + j]);
      Store4(t, Load4(t) - Load4(s + 4 * j));
    }
  }
  for (; r < num_rows; ++r) {
    PrefetchFactor<Pass::kForward>(supernode, block + r * width, width);
    double s[3];
    Dot1x3(block + r * width, p, padded, s);
    double* t = Row(y, rows[r]);
    t[0] -= s[0];
    t[1] -= s[1];
    t[2] -= s[2];
  }
}

// The batched backward pass takes a supernode's rows below its diagonal block in chunks, the last
// first, of about kBackwardChunkBytes of solution rows and factor rows each (at least
// kBackwardChunkMinRows rows): every block of columns and every strip of a row reads the chunk's
// rows again, and a chunk, smaller than an x86 core's L1 data cache, stays there between them.
// Taken whole, a supernode's rows below were read from the outer caches by each of its width / 4
// blocks of columns and each strip (eight times for a 16-wide supernode in a batch of eight
// frames). Chunks are faster on every mesh whose rows outgrow the nearest cache, and chunk sizes
// around this one measured alike (bench/RESULTS.md, "Batched solves").
constexpr std::int64_t kBackwardChunkBytes = 12 * 1024;
constexpr std::int64_t kBackwardChunkMinRows = 8;

// Calls chunk(begin, end) for the rows [begin, end) below `s`'s diagonal block, the last chunk
// first: chunks of about kBackwardChunkBytes of solution rows (`row_stride` doubles each) and
// factor rows, or all the rows in one when `whole`.
template <typename Value, typename Chunk>
inline void ForEachBackwardChunk(const SupernodeBlock<Value>& s, int row_stride, bool whole,
                                 Chunk&& chunk) {
  const std::int64_t row_bytes = row_stride * sizeof(double) + s.width * sizeof(Value);
  const std::int64_t rows =
      whole ? s.num_rows
            : std::max<std::int64_t>(kBackwardChunkMinRows, kBackwardChunkBytes / row_bytes);
  for (std::int64_t end = s.num_rows; end > s.width; end -= rows) {
    chunk(std::max<std::int64_t>(s.width, end - rows), end);
  }
}

// The three-column backward pass takes a supernode's rows below its diagonal block a strip of
// at most kStripVecs four-wide vectors of columns at a time, its sums in registers, and a block
// wider than one strip in chunks of rows (kBackwardChunkBytes, above), so that every strip
// reads a chunk from the nearest cache. Each row is read once by a strip, front to back, and
// the rows go last first: the factor is read as one descending stream, as the forward pass reads
// it ascending. Until then each four rows updated the supernode's planar unknowns in memory
// across the whole width (SubtractRows4x3: three loads and three stores for every four of the
// factor's values), and perf had the backward pass far above the forward pass over the same
// bytes; strips narrowed the gap (bench/RESULTS.md, "Triangular solve kernels").
//
// The three-column backward pass prefetches a factor that streams from memory in its own way.
// Each strip of columns reads a few lines of every row of a chunk, rows a block's width apart, so
// the first strip takes every row's lines as misses in a pattern the core's prefetchers do not
// follow. So the first strip of a chunk asks, as it reads row r, for row r - kBackwardRowsAhead
// whole into the nearest cache (every strip after it then reads the chunk from there), and for
// row r's lines kPrefetchBytes below into the outer caches, as the other passes do. The pair is
// what measured fastest on a Zen 5 with AVX-512; the nearest-cache prefetch carries most of the
// gain, and nearby look-aheads measured alike. (On a Zen 3, the outer-cache prefetch of every
// line alone made the solve slower; the pair has not been measured there.) The batched backward
// pass prefetches a line a row (BackwardColumnsMany), which measured faster than none. The
// figures: bench/RESULTS.md, "Triangular solve kernels" and "Batched solves".
//
// Its diagonal blocks (BackwardDiagonal, a block of four rows at a time) and its narrow
// supernodes' rows below (at once, as the forward pass's) ask for their lines kPrefetchBytes below
// too, so that the stream of requests runs on without a gap while the pass reads them (a large
// mesh's diagonal blocks hold a fair share of its factor's bytes): otherwise the bytes below each
// diagonal block are asked for by nobody (bench/RESULTS.md, "Triangular solve kernels").
constexpr int kStripVecs = 4;
constexpr std::int64_t kBackwardRowsAhead = 16;

// p's columns [first, first + 4 kVecs) -= sum over rows [begin, end) below `supernode`'s
// diagonal block (block row r there) * y[rows[r]], the rows taken last first.
template <typename Value, int kVecs>
inline void BackwardStrip(const SupernodeBlock<Value>& supernode, const Planar& p, int first,
                          const double* __restrict y, std::int64_t begin, std::int64_t end) {
  const Value* __restrict block = supernode.values + first;
  const int* __restrict rows = supernode.rows;
  const int width = supernode.width;
  const bool prefetch = supernode.prefetch && first == 0;
  const std::uintptr_t values = reinterpret_cast<std::uintptr_t>(supernode.values);
  const std::ptrdiff_t row_bytes = width * static_cast<std::ptrdiff_t>(sizeof(Value));
  Vec4 sx[kVecs], sy[kVecs], sz[kVecs];
  for (int v = 0; v < kVecs; ++v) sx[v] = sy[v] = sz[v] = Splat4(0);
  for (std::int64_t r = end - 1; r >= begin; --r) {
    const Value* row = block + r * width;
    if (prefetch) {
      PrefetchLinesNearest(values + (r - kBackwardRowsAhead) * row_bytes, row_bytes);
      PrefetchFactor<Pass::kBackward>(supernode, supernode.values + r * width, width);
    }
    const double* solved = Row(y, rows[r]);
    const Vec4 bx = Splat4(solved[0]), by = Splat4(solved[1]), bz = Splat4(solved[2]);
    for (int v = 0; v < kVecs; ++v) {
      const Vec4 w = Load4(row + 4 * v);
      sx[v] += w * bx;
      sy[v] += w * by;
      sz[v] += w * bz;
    }
  }
  for (int v = 0; v < kVecs; ++v) {
    const int k = first + 4 * v;
    Store4(p.x + k, Load4(p.x + k) - sx[v]);
    Store4(p.y + k, Load4(p.y + k) - sy[v]);
    Store4(p.z + k, Load4(p.z + k) - sz[v]);
  }
}

// p -= sum over `supernode`'s rows below its diagonal block of (block row r) * y[rows[r]]. A
// strip's last vector runs into the padding of p, reading the next row's values or the zeros
// that follow the factor's (see PlanarOf).
template <typename Value>
inline void BackwardUpdate(const SupernodeBlock<Value>& supernode, const Planar& p,
                           const double* __restrict y) {
  ZeroPadding(p, supernode.width);  // not read back, but kept finite
  const int padded = RoundUp4(supernode.width);
  const bool one_strip = padded <= 4 * kStripVecs;
  ForEachBackwardChunk(supernode, kRowStride, one_strip, [&](std::int64_t begin, std::int64_t end) {
    int first = 0;
    for (; first + 4 * kStripVecs <= padded; first += 4 * kStripVecs) {
      BackwardStrip<Value, kStripVecs>(supernode, p, first, y, begin, end);
    }
    WithCount<kStripVecs - 1>((padded - first) / 4, [&](auto vecs) {
      BackwardStrip<Value, decltype(vecs)::value>(supernode, p, first, y, begin, end);
    });
  });
}

// The narrow supernodes (most of them, holding few of the values) with the width fixed at
// compile time: each block row updates or reads one whole solution row.
template <typename Value, int kWidth>
inline void ForwardUpdateNarrow(const Value* __restrict block, const int* __restrict rows,
                                std::int64_t num_rows, const Planar& p, double* __restrict y) {
  Vec4 unknowns[kWidth];
  for (int k = 0; k < kWidth; ++k) unknowns[k] = MakeVec4(p.x[k], p.y[k], p.z[k], 0);
  for (std::int64_t r = kWidth; r < num_rows; ++r) {
    const Value* row = block + r * kWidth;
    double* t = Row(y, rows[r]);
    Vec4 v = Load4(t);
    for (int k = 0; k < kWidth; ++k) v -= Splat4(row[k]) * unknowns[k];
    Store4(t, v);
  }
}

// Two rows at a time into separate sums, so consecutive rows do not wait on each other's adds.
template <typename Value, int kWidth>
inline void BackwardUpdateNarrow(const Value* __restrict block, const int* __restrict rows,
                                 std::int64_t num_rows, const Planar& p,
                                 const double* __restrict y) {
  Vec4 even[kWidth], odd[kWidth];
  for (int k = 0; k < kWidth; ++k) even[k] = odd[k] = Splat4(0);
  std::int64_t r = kWidth;
  for (; r + 2 <= num_rows; r += 2) {
    const Value* row0 = block + r * kWidth;
    const Value* row1 = row0 + kWidth;
    const Vec4 z0 = Load4(Row(y, rows[r]));
    const Vec4 z1 = Load4(Row(y, rows[r + 1]));
    for (int k = 0; k < kWidth; ++k) {
      even[k] += Splat4(row0[k]) * z0;
      odd[k] += Splat4(row1[k]) * z1;
    }
  }
  if (r < num_rows) {
    const Value* row = block + r * kWidth;
    const Vec4 z = Load4(Row(y, rows[r]));
    for (int k = 0; k < kWidth; ++k) even[k] += Splat4(row[k]) * z;
  }
  for (int k = 0; k < kWidth; ++k) {
    const Vec4 sum = even[k] + odd[k];
    p.x[k] -= Lane(sum, 0);
    p.y[k] -= Lane(sum, 1);
    p.z[k] -= Lane(sum, 2);
  }
}

// Runs `pass` with the factor's value type: pass(double()) or pass(float()).
template <typename Pass>
inline void WithValueType(const SupernodalFactorView& f, Pass&& pass) {
  if (f.float_values != nullptr) {
    pass(float());
  } else {
    pass(double());
  }
}

// Supernode sn's step of the forward pass (L y = P b): its diagonal block solves its rows of y,
// which then update the rows below.
template <typename Value>
inline void ForwardSupernode(const SupernodalFactorView& f, int sn, double* __restrict y,
                             double* planar_buffer) {
  const SupernodeBlock<Value> s = BlockOf<Value>(f, sn);
  const Planar p = PlanarOf(planar_buffer, s.width);
  ForwardDiagonal(s, Row(y, s.first), p);
  if (s.width > 4) {
    ForwardUpdate(s, p, y);
  } else {
    PrefetchFactor<Pass::kForward>(s, s.values + s.width * s.width,
                                   (s.num_rows - s.width) * s.width);
    WithCount<4>(s.width, [&](auto w) {
      ForwardUpdateNarrow<Value, decltype(w)::value>(s.values, s.rows, s.num_rows, p, y);
    });
  }
}

// Supernode sn's step of the backward pass (L^T z = y): its rows subtract the rows below times
// their solved values, then the transposed diagonal block solves them.
template <typename Value>
inline void BackwardSupernode(const SupernodalFactorView& f, int sn, double* __restrict y,
                              double* planar_buffer) {
  const SupernodeBlock<Value> s = BlockOf<Value>(f, sn);
  const Planar p = PlanarOf(planar_buffer, s.width);
  double* ys = Row(y, s.first);
  for (int k = 0; k < s.width; ++k) {
    const double* t = Row(ys, k);
    p.x[k] = t[0];
    p.y[k] = t[1];
    p.z[k] = t[2];
  }
  if (s.width > 4) {
    BackwardUpdate(s, p, y);
  } else {
    PrefetchFactor<Pass::kBackward>(s, s.values + s.width * s.width,
                                    (s.num_rows - s.width) * s.width);
    WithCount<4>(s.width, [&](auto w) {
      BackwardUpdateNarrow<Value, decltype(w)::value>(s.values, s.rows, s.num_rows, p, y);
    });
  }
  BackwardDiagonal(s, ys, p);
}

// The forward pass over the listed supernodes only (ascending), on solution rows `y` (aligned
// as Solve3Impl's); the parallel solve's part (parallel_solve.h).
void ForwardListImpl(const SupernodalFactorView& f, const int* supernodes, int count, double* y,
                     double* planar_buffer) {
  WithValueType(f, [&](auto value) {
    using Value = decltype(value);
    for (int i = 0; i < count; ++i) ForwardSupernode<Value>(f, supernodes[i], y, planar_buffer);
  });
}

// The backward pass over the listed supernodes only (taken in descending order).
void BackwardListImpl(const SupernodalFactorView& f, const int* supernodes, int count, double* y,
                      double* planar_buffer) {
  WithValueType(f, [&](auto value) {
    using Value = decltype(value);
    for (int i = count - 1; i >= 0; --i) {
      BackwardSupernode<Value>(f, supernodes[i], y, planar_buffer);
    }
  });
}

void Solve3Impl(const SupernodalFactorView& f, const double* b, double* x, double* work) {
  const int n = f.size;
  // The solution rows start at the first 32-byte boundary of `work`.
  double* __restrict y = AlignedTo(work, kRowStride);
  double* const planar_buffer = y + kRowStride * static_cast<std::ptrdiff_t>(n);
  for (int unknown = 0; unknown < n; ++unknown) {
    const double* source = b + 3 * static_cast<std::ptrdiff_t>(unknown);
    double* t = Row(y, f.inverse_permutation[unknown]);
    t[0] = source[0];
    t[1] = source[1];
    t[2] = source[2];
    t[3] = 0;
  }
  WithValueType(f, [&](auto value) {
    using Value = decltype(value);
    for (int sn = 0; sn < f.num_supernodes; ++sn) ForwardSupernode<Value>(f, sn, y, planar_buffer);
    for (int sn = f.num_supernodes - 1; sn >= 0; --sn) {
      BackwardSupernode<Value>(f, sn, y, planar_buffer);
    }
  });
  for (int unknown = 0; unknown < n; ++unknown) {
    double* target = x + 3 * static_cast<std::ptrdiff_t>(unknown);
    const double* t = Row(y, f.inverse_permutation[unknown]);
    target[0] = t[0];
    target[1] = t[1];
    target[2] = t[2];
  }
}

// The backward half of Solve3: x = P^T L^-T z for z given in the factor's order (z[3 c + k], c a
// column of L), e.g. a combination of forward passes already made (CholeskyFactor::SolveBackward3).
void SolveBackward3Impl(const SupernodalFactorView& f, const double* z, double* x, double* work) {
  const int n = f.size;
  double* __restrict y = AlignedTo(work, kRowStride);
  double* const planar_buffer = y + kRowStride * static_cast<std::ptrdiff_t>(n);
  for (int column = 0; column < n; ++column) {
    const double* source = z + 3 * static_cast<std::ptrdiff_t>(column);
    double* t = Row(y, column);
    t[0] = source[0];
    t[1] = source[1];
    t[2] = source[2];
    t[3] = 0;
  }
  WithValueType(f, [&](auto value) {
    using Value = decltype(value);
    for (int sn = f.num_supernodes - 1; sn >= 0; --sn) {
      BackwardSupernode<Value>(f, sn, y, planar_buffer);
    }
  });
  for (int unknown = 0; unknown < n; ++unknown) {
    double* target = x + 3 * static_cast<std::ptrdiff_t>(unknown);
    const double* t = Row(y, f.inverse_permutation[unknown]);
    target[0] = t[0];
    target[1] = t[1];
    target[2] = t[2];
  }
}

// ---------------------------------------------------------------------------------------------
// Many right-hand sides at once (CholeskyFactor::SolveMany): one pass over the factor serves every
// column, so the factor's bytes are read once per batch instead of once per frame. The solution
// rows are kVecs batch vectors wide (columns padded with zeros to a multiple of kBatchLanes), and
// each factor value multiplies a whole row of them.
//
// A batch vector is one register of the widest width the variant is compiled for: eight doubles
// with AVX-512 (each broadcast factor value then serves twice the columns per instruction, and a
// batch of eight frames' 24 columns is three vectors), four elsewhere (Vec4).
#if defined(__AVX512F__)
typedef double BatchVec __attribute__((vector_size(64)));
typedef double BatchVecUnaligned __attribute__((vector_size(64), aligned(8), may_alias));
constexpr int kBatchLanes = 8;
inline BatchVec LoadBatch(const double* p) {
  return *reinterpret_cast<const BatchVecUnaligned*>(p);
}
inline void StoreBatch(double* p, BatchVec v) { *reinterpret_cast<BatchVecUnaligned*>(p) = v; }
inline BatchVec SplatBatch(double v) { return BatchVec{v, v, v, v, v, v, v, v}; }
#else
typedef Vec4 BatchVec;
constexpr int kBatchLanes = 4;
inline BatchVec LoadBatch(const double* p) { return Load4(p); }
inline void StoreBatch(double* p, BatchVec v) { Store4(p, v); }
inline BatchVec SplatBatch(double v) { return Splat4(v); }
#endif
static_assert(kBatchLanes <= kSolveBatchLanes, "SolveManyWorkSize must cover this variant's rows");

// Batch vectors in a row of `columns` columns (zero-padded).
constexpr int BatchVecsFor(int columns) { return (columns + kBatchLanes - 1) / kBatchLanes; }

// Register blocking of the batched passes. A row of kVecs batch vectors is taken in strips
// (StripsFor(kVecs) of them, StripVecs(kVecs) vectors at most each): the columns of a batch never
// mix, so each strip is solved on its own while the factor's rows it reads are still in the
// nearest cache. An update works on RowBlockFor(kVecs) solution rows (forward) or columns of the
// block (backward) at once, so that each load of a strip of a solution row serves all of them and
// their independent multiply-add chains hide the multiply-add's latency; the diagonal blocks are
// solved in tiles of as many rows. The block is the largest power of two up to eight whose
// accumulators (at most sixteen vectors), one strip of loaded vectors and a broadcast fit the
// registers.
//
// With AVX-512's thirty-two registers a strip is one vector, in blocks of 8 rows: each loaded
// solved vector serves eight rows. It measured faster than a whole row as one strip (a batch of
// eight frames: 3 vectors in blocks of 4 rows; sixteen: 6 in blocks of 2) at every batch size,
// and than strips of two or three vectors. With sixteen registers (AVX2, and SSE2's pairs)
// strips of at most three vectors, in blocks of 4 rows: 12 accumulators, 3 loaded vectors and a
// broadcast. A whole row of eight frames (6 vectors) allowed blocks of 2 rows only, and even
// their 12 accumulators and 6 loaded vectors did not fit: GCC read the solved vectors from memory
// at each multiply-add and kept sums on the stack. Strips of two were no faster than three. The
// figures: bench/RESULTS.md, "Batched solves".
#if defined(__AVX512F__)
constexpr int kBatchRegisters = 32;
constexpr int StripsFor(int vecs) { return vecs; }
#else
constexpr int kBatchRegisters = 16;
constexpr int StripsFor(int vecs) { return (vecs + 2) / 3; }
#endif
constexpr int StripVecs(int vecs) { return (vecs + StripsFor(vecs) - 1) / StripsFor(vecs); }
constexpr int RowBlockFor(int vecs) {
  const int strip = StripVecs(vecs);
  int block = 8;
  while (block > 1 && (block * strip > 16 || block * strip + strip + 1 > kBatchRegisters)) {
    block /= 2;
  }
  return block;
}

// Batch vectors [kFirst, kFirst + kCount) of a row: one strip.
template <int kFirst, int kCount>
struct Strip {
  static constexpr int first = kFirst;
  static constexpr int count = kCount;
};

template <int kVecs, typename Body, int... kIndices>
inline void ForEachStripOf(Body&& body, std::integer_sequence<int, kIndices...>) {
  constexpr int kStrips = StripsFor(kVecs);
  (body(Strip<kIndices * kVecs / kStrips,
              (kIndices + 1) * kVecs / kStrips - kIndices * kVecs / kStrips>()),
   ...);
}

// Calls body(Strip<first, count>()) for each strip of a row of kVecs batch vectors, in order.
template <int kVecs, typename Body>
inline void ForEachStrip(Body&& body) {
  ForEachStripOf<kVecs>(body, std::make_integer_sequence<int, StripsFor(kVecs)>());
}

// sum[i] -= (row i of `rows`, its first `count` values) * (the solved rows own[0, count), a strip
// of kCount vectors of rows kVecs vectors apart), for kRows rows of a supernode's block (`width`
// values each) whose sums are held in registers.
//
// Always inlined: GCC kept some instances out of line, and the caller's sums then went through
// the stack at every block of rows, a narrow supernode's few values each; inlined, every mesh's
// batches measured faster (bench/RESULTS.md, "Batched solves").
template <typename Value, int kVecs, int kCount, int kRows>
__attribute__((always_inline)) inline void SubtractSolvedColumns(
    const Value* __restrict rows, int width, int count, const double* __restrict own,
    BatchVec (&sum)[kRows][kCount], const SpreadPrefetch& prefetch = {}) {
  constexpr int kStride = kBatchLanes * kVecs;
  for (int k = 0; k < count; ++k) {
    prefetch.Step(k);
    const double* known = own + kStride * k;
    BatchVec v[kCount];
    for (int j = 0; j < kCount; ++j) v[j] = LoadBatch(known + kBatchLanes * j);
    for (int i = 0; i < kRows; ++i) {
      const BatchVec l = SplatBatch(rows[i * width + k]);
      for (int j = 0; j < kCount; ++j) sum[i][j] -= l * v[j];
    }
  }
  prefetch.Rest(count);
}

// The block's prefetches are spread over the first strip's loop only (the others read the same
// rows again, from the nearest cache).
template <typename StripType>
inline SpreadPrefetch PrefetchFor(StripType, const SpreadPrefetch& prefetch) {
  return StripType::first == 0 ? prefetch : SpreadPrefetch{};
}

// Rows [r, num_rows) of the block below the diagonal, kRows at a time while they last, then in
// halving blocks: y[rows[i]] -= (block row i) * (the supernode's solved rows `own`).
template <typename Value, int kVecs, int kRows>
inline void ForwardRowsMany(const SupernodeBlock<Value>& s, const double* __restrict own,
                            double* __restrict y, std::int64_t r) {
  constexpr int kStride = kBatchLanes * kVecs;
  const int width = s.width;
  for (; r + kRows <= s.num_rows; r += kRows) {
    const Value* block_rows = s.values + r * width;
    const auto prefetch = SpreadPrefetch::Of<Pass::kForward>(s, block_rows, kRows * width);
    double* target[kRows];
    for (int i = 0; i < kRows; ++i) {
      target[i] = y + kStride * static_cast<std::ptrdiff_t>(s.rows[r + i]);
    }
    ForEachStrip<kVecs>([&](auto strip) {
      constexpr int kFirst = decltype(strip)::first, kCount = decltype(strip)::count;
      BatchVec sum[kRows][kCount];
      for (int i = 0; i < kRows; ++i) {
        for (int j = 0; j < kCount; ++j)
          sum[i][j] = LoadBatch(target[i] + kBatchLanes * (kFirst + j));
      }
      SubtractSolvedColumns<Value, kVecs, kCount, kRows>(
          block_rows, width, width, own + kBatchLanes * kFirst, sum, PrefetchFor(strip, prefetch));
      for (int i = 0; i < kRows; ++i) {
        for (int j = 0; j < kCount; ++j)
          StoreBatch(target[i] + kBatchLanes * (kFirst + j), sum[i][j]);
      }
    });
  }
  if constexpr (kRows > 1) ForwardRowsMany<Value, kVecs, kRows / 2>(s, own, y, r);
}

// Forward substitution with the diagonal block on the supernode's own rows from `c` on: kTile
// rows at a time while they last, then in halving tiles, each tile first subtracting the columns
// already solved (register-blocked as the rows below), then solving its own small triangle in
// registers. One division per row, not one per vector: a vector division takes several times a
// multiplication's issue slots.
template <typename Value, int kVecs, int kTile>
inline void ForwardDiagonalMany(const SupernodeBlock<Value>& s, double* __restrict own, int c) {
  constexpr int kStride = kBatchLanes * kVecs;
  const int width = s.width;
  for (; c + kTile <= width; c += kTile) {
    const Value* tile_rows = s.values + static_cast<std::ptrdiff_t>(c) * width;
    const auto prefetch = SpreadPrefetch::Of<Pass::kForward>(s, tile_rows, kTile * width);
    ForEachStrip<kVecs>([&](auto strip) {
      constexpr int kFirst = decltype(strip)::first, kCount = decltype(strip)::count;
      double* const tile = own + kStride * c + kBatchLanes * kFirst;
      BatchVec sum[kTile][kCount];
      for (int i = 0; i < kTile; ++i) {
        for (int j = 0; j < kCount; ++j)
          sum[i][j] = LoadBatch(tile + kStride * i + kBatchLanes * j);
      }
      SubtractSolvedColumns<Value, kVecs, kCount, kTile>(
          tile_rows, width, c, own + kBatchLanes * kFirst, sum, PrefetchFor(strip, prefetch));
      // The triangle's loops unrolled whole, so the tile's sums stay in registers: left to
      // itself GCC keeps these loops (their bound varies with `i`) and with them the sums on the
      // stack, each multiply-add a load and a store (about a tenth of the batched passes' time).
#pragma GCC unroll 8
      for (int i = 0; i < kTile; ++i) {
        const Value* row = tile_rows + i * width;
#pragma GCC unroll 8
        for (int m = 0; m < i; ++m) {
          const BatchVec l = SplatBatch(row[c + m]);
          for (int j = 0; j < kCount; ++j) sum[i][j] -= l * sum[m][j];
        }
        const BatchVec inverse_pivot = SplatBatch(1.0 / static_cast<double>(row[c + i]));
        for (int j = 0; j < kCount; ++j) {
          sum[i][j] = sum[i][j] * inverse_pivot;
          StoreBatch(tile + kStride * i + kBatchLanes * j, sum[i][j]);
        }
      }
    });
  }
  if constexpr (kTile > 1) ForwardDiagonalMany<Value, kVecs, kTile / 2>(s, own, c);
}

// Forward pass of one supernode: its diagonal block solves its own rows (contiguous in y), then
// every row below subtracts its block row times them.
template <typename Value, int kVecs>
inline void ForwardSupernodeMany(const SupernodeBlock<Value>& s, double* __restrict y) {
  constexpr int kStride = kBatchLanes * kVecs;
  double* __restrict own = y + kStride * static_cast<std::ptrdiff_t>(s.first);
  ForwardDiagonalMany<Value, kVecs, RowBlockFor(kVecs)>(s, own, 0);
  ForwardRowsMany<Value, kVecs, RowBlockFor(kVecs)>(s, own, y, s.width);
}

// Columns [k, width) of the block: own[c] -= sum over the block's rows [begin, end) (below the
// diagonal: begin >= width) of (block column c) * (their solved rows), kColumns columns at a time
// while they last, then in halving blocks. Where the columns' sums are fewer than eight vectors
// (narrow supernodes, small batches), the rows alternate between kSplits sets of sums, so that
// consecutive rows do not wait on each other's multiply-adds.
template <typename Value, int kVecs, int kColumns>
inline void BackwardColumnsMany(const SupernodeBlock<Value>& s, double* __restrict own,
                                const double* __restrict y, int k, std::int64_t begin,
                                std::int64_t end) {
  constexpr int kStride = kBatchLanes * kVecs;
  const int width = s.width;
  for (; k + kColumns <= width; k += kColumns) {
    ForEachStrip<kVecs>([&](auto strip) {
      constexpr int kFirst = decltype(strip)::first, kCount = decltype(strip)::count;
      constexpr int kSplits = kColumns * kCount >= 8 ? 1 : kColumns * kCount >= 4 ? 2 : 4;
      BatchVec sum[kSplits][kColumns][kCount];
      for (int u = 0; u < kSplits; ++u) {
        for (int c = 0; c < kColumns; ++c) {
          for (int j = 0; j < kCount; ++j) sum[u][c][j] = SplatBatch(0);
        }
      }
      const auto add_row = [&](std::int64_t row_index, BatchVec(&into)[kColumns][kCount]) {
        const Value* row = s.values + row_index * width + k;
        // The block's stream below, a line a row as each strip of columns reads its own.
        if constexpr (kFirst == 0) SpreadPrefetch::Of<Pass::kBackward>(s, row, 1).Step(0);
        const double* solved =
            y + kStride * static_cast<std::ptrdiff_t>(s.rows[row_index]) + kBatchLanes * kFirst;
        BatchVec v[kCount];
        for (int j = 0; j < kCount; ++j) v[j] = LoadBatch(solved + kBatchLanes * j);
        for (int c = 0; c < kColumns; ++c) {
          const BatchVec l = SplatBatch(row[c]);
          for (int j = 0; j < kCount; ++j) into[c][j] += l * v[j];
        }
      };
      // The last rows first: the backward pass reads the factor descending (PrefetchFactor).
      std::int64_t r = end;
      for (; r - kSplits >= begin; r -= kSplits) {
        for (int u = 0; u < kSplits; ++u) add_row(r - kSplits + u, sum[u]);
      }
      for (; r > begin; --r) add_row(r - 1, sum[0]);
      for (int u = 1; u < kSplits; ++u) {
        for (int c = 0; c < kColumns; ++c) {
          for (int j = 0; j < kCount; ++j) sum[0][c][j] += sum[u][c][j];
        }
      }
      for (int c = 0; c < kColumns; ++c) {
        double* target = own + kStride * (k + c) + kBatchLanes * kFirst;
        for (int j = 0; j < kCount; ++j) {
          StoreBatch(target + kBatchLanes * j, LoadBatch(target + kBatchLanes * j) - sum[0][c][j]);
        }
      }
    });
  }
  if constexpr (kColumns > 1) {
    BackwardColumnsMany<Value, kVecs, kColumns / 2>(s, own, y, k, begin, end);
  }
}

// Back substitution with the transposed diagonal block on the supernode's rows [0, c), the last
// first: kTile rows at a time while they last, then in halving tiles, each tile solving its small
// triangle in registers and then subtracting its solved rows from every row above it in one load
// and store per row.
template <typename Value, int kVecs, int kTile>
inline void BackwardDiagonalMany(const SupernodeBlock<Value>& s, double* __restrict own, int c) {
  constexpr int kStride = kBatchLanes * kVecs;
  const int width = s.width;
  for (; c >= kTile; c -= kTile) {
    const int f = c - kTile;
    const Value* tile_rows = s.values + static_cast<std::ptrdiff_t>(f) * width;
    const auto prefetch = SpreadPrefetch::Of<Pass::kBackward>(s, tile_rows, kTile * width);
    ForEachStrip<kVecs>([&](auto strip) {
      constexpr int kFirst = decltype(strip)::first, kCount = decltype(strip)::count;
      double* const tile = own + kStride * f + kBatchLanes * kFirst;
      BatchVec solved[kTile][kCount];
      // Unrolled whole, as in ForwardDiagonalMany, so `solved` stays in registers.
#pragma GCC unroll 8
      for (int i = kTile - 1; i >= 0; --i) {
        const Value* row = tile_rows + i * width;
        double* const target = tile + kStride * i;
        for (int j = 0; j < kCount; ++j) solved[i][j] = LoadBatch(target + kBatchLanes * j);
#pragma GCC unroll 8
        for (int m = kTile - 1; m > i; --m) {
          const BatchVec l = SplatBatch(tile_rows[m * width + f + i]);
          for (int j = 0; j < kCount; ++j) solved[i][j] -= l * solved[m][j];
        }
        const BatchVec inverse_pivot = SplatBatch(1.0 / static_cast<double>(row[f + i]));
        for (int j = 0; j < kCount; ++j) {
          solved[i][j] = solved[i][j] * inverse_pivot;
          StoreBatch(target + kBatchLanes * j, solved[i][j]);
        }
      }
      const SpreadPrefetch strip_prefetch = PrefetchFor(strip, prefetch);
      for (int k = 0; k < f; ++k) {
        strip_prefetch.Step(k);
        double* above = own + kStride * k + kBatchLanes * kFirst;
        BatchVec sum[kCount];
        for (int j = 0; j < kCount; ++j) sum[j] = LoadBatch(above + kBatchLanes * j);
        for (int i = 0; i < kTile; ++i) {
          const BatchVec l = SplatBatch(tile_rows[i * width + k]);
          for (int j = 0; j < kCount; ++j) sum[j] -= l * solved[i][j];
        }
        for (int j = 0; j < kCount; ++j) StoreBatch(above + kBatchLanes * j, sum[j]);
      }
    });
    prefetch.Rest(f);
  }
  if constexpr (kTile > 1) BackwardDiagonalMany<Value, kVecs, kTile / 2>(s, own, c);
}

// Backward pass of one supernode: its own rows subtract the block's rows below times the solved
// rows there (a chunk of rows at a time, columns of the block taken together, the sums kept in
// registers), then the transposed diagonal block solves them, last row first.
template <typename Value, int kVecs>
inline void BackwardSupernodeMany(const SupernodeBlock<Value>& s, double* __restrict y) {
  constexpr int kStride = kBatchLanes * kVecs;
  double* __restrict own = y + kStride * static_cast<std::ptrdiff_t>(s.first);
  ForEachBackwardChunk(s, kStride, false, [&](std::int64_t begin, std::int64_t end) {
    BackwardColumnsMany<Value, kVecs, RowBlockFor(kVecs)>(s, own, y, 0, begin, end);
  });
  BackwardDiagonalMany<Value, kVecs, RowBlockFor(kVecs)>(s, own, s.width);
}

// The batched passes on solution rows of kVecs batch vectors: gather(row, unknown) fills the row
// of `unknown` (its first columns; the rest is zeroed here) from that unknown's right-hand sides,
// scatter(row, unknown) takes its solution back out; both in the unknowns' order.
template <int kVecs, typename Gather, typename Scatter>
void SolveRowsWithWidth(const SupernodalFactorView& f, int columns, double* work, Gather&& gather,
                        Scatter&& scatter) {
  constexpr int kStride = kBatchLanes * kVecs;
  const int n = f.size;
  double* __restrict y = AlignedTo(work, kBatchLanes);  // at a whole batch vector's boundary
  const auto row_of = [&](int unknown) {
    return y + kStride * static_cast<std::ptrdiff_t>(f.inverse_permutation[unknown]);
  };
  for (int unknown = 0; unknown < n; ++unknown) {
    if (unknown + kBatchRowsAhead < n) PrefetchBatchRow(row_of(unknown + kBatchRowsAhead), kStride);
    double* t = row_of(unknown);
    gather(t, unknown);
    for (int c = columns; c < kStride; ++c) t[c] = 0;
  }
  WithValueType(f, [&](auto value) {
    using Value = decltype(value);
    for (int sn = 0; sn < f.num_supernodes; ++sn) {
      ForwardSupernodeMany<Value, kVecs>(BlockOf<Value>(f, sn), y);
    }
    for (int sn = f.num_supernodes - 1; sn >= 0; --sn) {
      BackwardSupernodeMany<Value, kVecs>(BlockOf<Value>(f, sn), y);
    }
  });
  for (int unknown = 0; unknown < n; ++unknown) {
    if (unknown + kBatchRowsAhead < n) PrefetchBatchRow(row_of(unknown + kBatchRowsAhead), kStride);
    scatter(row_of(unknown), unknown);
  }
}

void SolveManyImpl(const SupernodalFactorView& f, const double* b, double* x, int columns,
                   double* work) {
  WithCount<BatchVecsFor(kMaxSolveColumns)>(BatchVecsFor(columns), [&](auto vecs) {
    SolveRowsWithWidth<decltype(vecs)::value>(
        f, columns, work,
        [&](double* __restrict row, int unknown) {
          const double* source = b + static_cast<std::ptrdiff_t>(columns) * unknown;
          for (int c = 0; c < columns; ++c) row[c] = source[c];
        },
        [&](const double* __restrict row, int unknown) {
          double* target = x + static_cast<std::ptrdiff_t>(columns) * unknown;
          for (int c = 0; c < columns; ++c) target[c] = row[c];
        });
  });
}

// The frames' count fixed at compile time, so each row's gather and scatter unroll.
void SolveFramesImpl(const SupernodalFactorView& f, const double* const* b, double* const* x,
                     int frames, double* work) {
  WithCount<kMaxSolveColumns / 3>(frames, [&](auto count) {
    constexpr int kFrames = decltype(count)::value;
    SolveRowsWithWidth<BatchVecsFor(3 * kFrames)>(
        f, 3 * kFrames, work,
        [&](double* __restrict row, int unknown) {
          for (int frame = 0; frame < kFrames; ++frame) {
            const double* source = b[frame] + 3 * static_cast<std::ptrdiff_t>(unknown);
            row[3 * frame] = source[0];
            row[3 * frame + 1] = source[1];
            row[3 * frame + 2] = source[2];
          }
        },
        [&](const double* __restrict row, int unknown) {
          for (int frame = 0; frame < kFrames; ++frame) {
            double* target = x[frame] + 3 * static_cast<std::ptrdiff_t>(unknown);
            target[0] = row[3 * frame];
            target[1] = row[3 * frame + 1];
            target[2] = row[3 * frame + 2];
          }
        });
  });
}

// Runs body(vecs, value) with the batch vectors a row of `columns` takes (a Count) and the
// factor's value type (a double or a float).
template <typename Body>
inline void WithBatchShape(const SupernodalFactorView& f, int columns, Body&& body) {
  WithCount<BatchVecsFor(kMaxSolveColumns)>(BatchVecsFor(columns), [&](auto vecs) {
    WithValueType(f, [&](auto value) { body(vecs, value); });
  });
}

// One direction's batched pass over the listed supernodes only (forward: ascending, backward:
// taken in descending order), on solution rows of BatchVecsFor(columns) batch vectors each: the
// parallel batched solve's parts (parallel_solve.h).
void ForwardListManyImpl(const SupernodalFactorView& f, const int* supernodes, int count, double* y,
                         int columns) {
  WithBatchShape(f, columns, [&](auto vecs, auto value) {
    using Value = decltype(value);
    for (int i = 0; i < count; ++i) {
      ForwardSupernodeMany<Value, decltype(vecs)::value>(BlockOf<Value>(f, supernodes[i]), y);
    }
  });
}

void BackwardListManyImpl(const SupernodalFactorView& f, const int* supernodes, int count,
                          double* y, int columns) {
  WithBatchShape(f, columns, [&](auto vecs, auto value) {
    using Value = decltype(value);
    for (int i = count - 1; i >= 0; --i) {
      BackwardSupernodeMany<Value, decltype(vecs)::value>(BlockOf<Value>(f, supernodes[i]), y);
    }
  });
}

// The backward pass alone on `columns` columns given in the factor's order (SolveBackwardMany):
// one pass over the factor for all of them, as SolveManyImpl's second half.
void SolveBackwardManyImpl(const SupernodalFactorView& f, const double* z, double* x, int columns,
                           double* work) {
  WithBatchShape(f, columns, [&](auto vecs, auto value) {
    using Value = decltype(value);
    constexpr int kStride = kBatchLanes * decltype(vecs)::value;
    const int n = f.size;
    double* __restrict y = AlignedTo(work, kBatchLanes);
    for (int column = 0; column < n; ++column) {
      const double* source = z + static_cast<std::ptrdiff_t>(columns) * column;
      double* t = y + kStride * static_cast<std::ptrdiff_t>(column);
      for (int c = 0; c < columns; ++c) t[c] = source[c];
      for (int c = columns; c < kStride; ++c) t[c] = 0;
    }
    for (int sn = f.num_supernodes - 1; sn >= 0; --sn) {
      BackwardSupernodeMany<Value, decltype(vecs)::value>(BlockOf<Value>(f, sn), y);
    }
    for (int unknown = 0; unknown < n; ++unknown) {
      const double* t = y + kStride * static_cast<std::ptrdiff_t>(f.inverse_permutation[unknown]);
      if (unknown + kBatchRowsAhead < n) {
        PrefetchBatchRow(y + kStride * static_cast<std::ptrdiff_t>(
                                           f.inverse_permutation[unknown + kBatchRowsAhead]),
                         kStride);
      }
      double* target = x + static_cast<std::ptrdiff_t>(columns) * unknown;
      for (int c = 0; c < columns; ++c) target[c] = t[c];
    }
  });
}

}  // namespace
}  // namespace deform

#pragma GCC diagnostic pop
