// The forward pass of a solve for one unit right-hand side, kept sparse: what low-rank terms on
// the factor (contact constraints: core/constraints) need of M^-1 without k full solves. Internal
// to the solver; CholeskyFactor::ForwardUnitSolve is the interface.
#pragma once

#include <cstdint>

#include "core/solver/supernodal_solve.h"

namespace deform {

// y = L^-1 P e_i on the supernodes of the elimination tree's path from the one holding i's
// permuted column to the root (y is zero elsewhere). See CholeskyFactor::ForwardUnitSolve.
int ForwardUnitSolve(const SupernodalFactorView& factor, int i, int* path, double* values,
                     std::int64_t max_values, double* work);

// Unit right-hand sides solved together by ForwardUnitSolves: each supernode's block is read once
// for this many paths.
inline constexpr int kUnitSolveBlock = 8;

// ForwardUnitSolve for `count` unit right-hand sides e_{columns[t]} at once, kUnitSolveBlock at a
// time: path t's supernodes into paths[t * path_stride ...], its length into lengths[t], its values
// into values[t * value_stride ...] (value_stride at least the longest path's columns, path_stride
// its supernodes: LongestUnitSolvePath). The same values as ForwardUnitSolve, summed in the same
// order. `work`: size * kUnitSolveBlock doubles, zero on entry and left zero. Allocation-free.
void ForwardUnitSolves(const SupernodalFactorView& factor, const int* columns, int count,
                       int* paths, int path_stride, int* lengths, double* values,
                       std::int64_t value_stride, double* work);

// The most columns, and the most supernodes, on one leaf-to-root path.
void LongestUnitSolvePath(const SupernodalFactorView& factor, std::int64_t* columns,
                          int* supernodes);

}  // namespace deform
