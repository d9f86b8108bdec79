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

// The most columns, and the most supernodes, on one leaf-to-root path.
void LongestUnitSolvePath(const SupernodalFactorView& factor, std::int64_t* columns,
                          int* supernodes);

}  // namespace deform
