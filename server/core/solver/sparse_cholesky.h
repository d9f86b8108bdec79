// A factor-once, solve-many sparse Cholesky for the symmetric positive definite normal equations.
//
// SymbolicCholesky::Analyze() depends only on the sparsity pattern: fill-reducing ordering,
// elimination tree and the pattern of the factor. CholeskyFactor::Factorize() computes the numeric
// factor L (P A P^T = L L^T) for any matrix with that same pattern, reusing the analysis; it is
// called once per mesh and again after each stiffness change.
//
// The solve is written for the deformation's three right-hand sides (x, y, z): they are stored
// interleaved and solved together, so each triangular pass reads the factor exactly once. The
// factor is stored by supernodes (runs of columns sharing one row pattern, kept as dense row-major
// blocks with one row index per block row), so a pass reads 8 bytes per stored value plus little
// else, and its inner loops are dense. This makes the per-frame solve memory-bound.
#pragma once

#include "core/solver/cholesky_factor.h"    // numeric factor and solve
#include "core/solver/ordering.h"           // fill-reducing orderings
#include "core/solver/symbolic_cholesky.h"  // symbolic analysis
