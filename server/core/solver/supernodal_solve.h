// The two triangular passes of CholeskyFactor::Solve3, behind a plain view of the factor so they
// can be compiled once per instruction set (supernodal_solve_impl.h) and picked at run time.
// Internal to the core: CholeskyFactor is the interface; tests use this header to check that every
// compiled variant gives the same answer.
#pragma once

#include <cstddef>
#include <cstdint>

namespace deform {

// The supernodal factor as CholeskyFactor stores it (see sparse_cholesky.h): supernode s holds
// columns [supernode_columns[s], supernode_columns[s + 1]); its rows are
// row_indices[row_pointers[s] .. row_pointers[s + 1]) (its own columns first, then the rows below,
// ascending), and its values a dense row-major (#rows) x (width) block at
// values[value_pointers[s]], zero above the diagonal, and `values` is followed by at least
// kSolveValuePadding readable zeros. permutation[new] = old, inverse_permutation[old] = new (the
// passes gather the right-hand sides and scatter the solution in the unknowns' order, reading and
// writing b and x once through, the solution rows being the scattered side). A float32 factor sets
// `float_values` (same layout and padding) instead of `values`: exactly one of the two is set. The
// passes read float32 values widened to double and do all their arithmetic in double either way.
inline constexpr int kSolveValuePadding = 3;

struct SupernodalFactorView {
  int size = 0;
  int num_supernodes = 0;
  const int* supernode_columns = nullptr;
  const int* permutation = nullptr;
  const int* inverse_permutation = nullptr;
  const std::int64_t* row_pointers = nullptr;
  const std::int64_t* value_pointers = nullptr;
  const int* row_indices = nullptr;
  const double* values = nullptr;
  const float* float_values = nullptr;
};

// The solution during a three-column solve: one row of four doubles per unknown (x, y, z and a
// zero), so a row is one aligned four-wide load or store wherever the narrow supernodes scatter or
// gather.
inline constexpr int kSolveRowStride = 4;

// Doubles of one solve's buffers: its solution rows and three padded columns for the widest
// supernode (its unknowns kept planar while its block is applied).
inline std::int64_t SolveBuffersSize(int size, int widest_supernode) {
  return kSolveRowStride * static_cast<std::int64_t>(size) + 3 * ((widest_supernode + 3) & ~3);
}

// Solves P^T L L^T P x = b for three right-hand sides stored interleaved (b[3 i + c]). `x` may
// equal `b`; `work` holds SolveWorkSize() doubles. Reads the factor once per pass and allocates
// nothing. Doubles of `work` a solve needs: its buffers, and slack to align the rows to 32 bytes.
inline std::int64_t SolveWorkSize(int size, int widest_supernode) {
  return SolveBuffersSize(size, widest_supernode) + kSolveRowStride;
}

using Solve3Function = void (*)(const SupernodalFactorView& factor, const double* b, double* x,
                                double* work);

// Solves P^T L L^T P X = B for `columns` right-hand sides (1 to kMaxSolveColumns) stored by rows:
// b[columns * i + c]. `x` may equal `b`; `work` holds SolveManyWorkSize() doubles. One pass over
// the factor per direction for all the columns; allocates nothing. Each column's result equals
// Solve3's for that column to round-off (the sums run in another order).
inline constexpr int kMaxSolveColumns = 48;  // sixteen frames of three coordinates
// The widest batch vector of any variant, in doubles (AVX-512's eight): a batch's solution rows
// are padded to a multiple of it and aligned to it.
inline constexpr int kSolveBatchLanes = 8;
inline std::int64_t SolveManyWorkSize(int size, int columns) {
  return kSolveBatchLanes *
             ((static_cast<std::int64_t>(columns) + kSolveBatchLanes - 1) / kSolveBatchLanes) *
             size +
         kSolveBatchLanes;
}
using SolveManyFunction = void (*)(const SupernodalFactorView& factor, const double* b, double* x,
                                   int columns, double* work);
// The same for `frames` frames (1 to kMaxSolveColumns / 3) whose three columns each stay in
// arrays of their own, interleaved (b[f][3 i + c]): gathered into the batch and scattered back
// in the same passes that apply the permutation, with no packed copy. x[f] may equal b[f]; `work`
// holds SolveManyWorkSize(size, 3 * frames) doubles.
// The backward pass alone for `columns` (1 to kMaxSolveColumns) columns z given in the factor's
// order (z[columns * c + k], c a column of L): x = P^T L^-T z, stored by rows as SolveMany's. `x`
// may equal `z`; `work` holds SolveManyWorkSize() doubles. Allocates nothing.
using SolveBackwardManyFunction = void (*)(const SupernodalFactorView& factor, const double* z,
                                           double* x, int columns, double* work);
using SolveFramesFunction = void (*)(const SupernodalFactorView& factor, const double* const* b,
                                     double* const* x, int frames, double* work);

enum class SolveKernel {
  kBaseline,  // any CPU the project builds for
  kAvx2Fma,   // x86-64 with AVX2 and FMA (checked at run time)
  kAvx512,    // x86-64 with AVX-512 F and VL as well: the batched passes eight doubles wide
};

const char* SolveKernelName(SolveKernel kernel);
// Whether this build has the kernel and this CPU can run it.
bool SolveKernelAvailable(SolveKernel kernel);
// The fastest available kernel, chosen once per process.
SolveKernel BestSolveKernel();
// One direction's pass over the listed supernodes only (forward: ascending, backward: taken in
// descending order), on solution rows `y` aligned to 32 bytes and a planar buffer for the widest
// supernode; the parts of the parallel solve (parallel_solve.h).
using SupernodeListPass = void (*)(const SupernodalFactorView& factor, const int* supernodes,
                                   int count, double* y, double* planar_buffer);

// The same for the batched passes: solution rows of `columns` right-hand sides, each row padded
// to BatchRowStride(batch_lanes, columns) doubles (the kernel's batch_lanes) and aligned to it.
using SupernodeListManyPass = void (*)(const SupernodalFactorView& factor, const int* supernodes,
                                       int count, double* y, int columns);
// Doubles per solution row of a batch of `columns` with `lanes` doubles per batch vector.
inline int BatchRowStride(int lanes, int columns) {
  return lanes * ((columns + lanes - 1) / lanes);
}

// A batch's gather and scatter go through the unknowns in order (b and x read and written once
// through); each unknown's solution row, kBatchRowsAhead unknowns on, is asked for into the
// nearest cache (PrefetchBatchRow) while the row in hand is copied: the rows are the scattered
// side, a few cache lines each anywhere in the batch's solution rows, which outgrow the core's
// own cache once a mesh has tens of thousands of vertices. Split batches (ParallelSolveFrames,
// which also fixes the frame count at compile time, as SolveFrames does) and unsplit ones
// measured faster with it where the rows outgrow the core's cache, alike where they fit.
// Solve3's rows (four doubles, one line) are not prefetched: there the same gained nothing. The
// figures: bench/RESULTS.md, "Batched solves" and "Triangular solve kernels".
inline constexpr int kBatchRowsAhead = 8;

// Asks for the cache lines of [address, address + bytes) into the nearest cache (prefetcht0;
// inline assembly on x86, as PrefetchLine in supernodal_solve_impl.h explains). The address is an
// integer, so it may lie outside any array (a prefetch never faults).
inline void PrefetchLinesNearest(std::uintptr_t address, std::ptrdiff_t bytes) {
  const std::uintptr_t end = address + static_cast<std::uintptr_t>(bytes);
  for (std::uintptr_t line = address & ~std::uintptr_t{63}; line < end; line += 64) {
#if defined(__x86_64__) || defined(__i386__)
    asm volatile("prefetcht0 %0" : : "m"(*reinterpret_cast<const char*>(line)));
#else
    __builtin_prefetch(reinterpret_cast<const void*>(line), 0, 3);
#endif
  }
}

// The cache lines of `doubles` doubles from `row`, into the nearest cache.
inline void PrefetchBatchRow(const double* row, int doubles) {
  PrefetchLinesNearest(reinterpret_cast<std::uintptr_t>(row),
                       static_cast<std::ptrdiff_t>(doubles) * sizeof(double));
}

// Whether the three-column forward pass asks for a factor streamed from memory non-temporally
// (prefetchnta: into the nearest cache, not kept in the outer ones as it leaves) rather than into
// the outer caches: on AMD's processors, whose last-level cache is filled by what the cores' L2
// evicts (measured: kPrefetchBytes in supernodal_solve_impl.h). Decided once, by the CPU's vendor.
bool ForwardStreamIsNonTemporal();

// One kernel's passes: supernodal_solve_impl.h compiled for its instruction set.
struct SolveKernelFunctions {
  Solve3Function solve3;
  SolveManyFunction solve_many;
  SolveFramesFunction solve_frames;
  SupernodeListPass forward_list;
  SupernodeListPass backward_list;
  int batch_lanes;  // doubles per batch vector (at most kSolveBatchLanes)
  SupernodeListManyPass forward_list_many;
  SupernodeListManyPass backward_list_many;
  Solve3Function solve_backward3;  // x = P^T L^-T z, z in the factor's order
  SolveBackwardManyFunction solve_backward_many;
};
// The kernel's passes; it must be available.
const SolveKernelFunctions& SolveKernelFunctionsFor(SolveKernel kernel);

}  // namespace deform
