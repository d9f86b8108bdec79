// Fill-reducing orderings for the sparse Cholesky (symbolic_cholesky.h): which permutation P makes
// the factor of P A P^T sparse.
#pragma once

#include <Eigen/SparseCore>
#include <string_view>
#include <vector>

#include "core/base/status.h"

namespace deform {

enum class Ordering {
  kNatural,  // no reordering (for tests)
  kAmd,      // approximate minimum degree (Eigen's)
  kMetis,    // nested dissection (METIS_NodeND); least fill on large surface meshes
  kAuto,     // both of the above, keeping the one whose factor has fewer non-zeros (AMD tends to
             // win below a few thousand vertices, METIS above); SymbolicCholesky::Analyze does so
};

// "natural", "amd", "metis", "auto".
const char* OrderingName(Ordering ordering);
// The ordering OrderingName() names; INVALID_ARGUMENT listing the names for any other text.
StatusOr<Ordering> OrderingFromName(std::string_view name);

// The permutation `ordering` chooses for the pattern of `a` (square, both triangles stored,
// column-major), as permutation[new] = old. Deterministic from run to run, whatever other threads
// do meanwhile (METIS's calls take turns, and its rand() is each thread's own: ordering.cc).
// INVALID_ARGUMENT for kAuto (which compares whole analyses, see above); INTERNAL if METIS fails.
StatusOr<std::vector<int>> FillReducingOrdering(
    const Eigen::SparseMatrix<double, Eigen::ColMajor, int>& a, Ordering ordering);

}  // namespace deform
