// The arithmetic limit of the batched solves: how many multiply-adds one thread does a second in
// the instruction set of a solve kernel (CholeskyFactor::SolveFrames multiplies each of the
// factor's values into whole vectors of a batch's solution row, so a batch of several frames
// meets this limit before the bytes' bound).
#pragma once

#include "core/solver/supernodal_solve.h"

namespace deform::bench {

// Double-precision multiply-adds a second on one thread (each lane of a vector counts) with
// `kernel`'s instructions: AVX-512's eight-double FMA, AVX2's four-double FMA, or the baseline's
// two-double multiply and add (SSE2 on x86-64). The best of `repeats` timed runs after a warm-up;
// `kernel` must be available (SolveKernelAvailable).
double MeasureMultiplyAddRate(SolveKernel kernel, int repeats = 5);

}  // namespace deform::bench
