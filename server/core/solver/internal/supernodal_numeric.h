// The supernodal numeric factorization's kernel (private to the solver): left-looking over the
// supernodes, each supernode's block assembled from C's lower triangle, updated by every
// descendant that has rows in its columns (one dense product each), then factorized in place (a
// dense Cholesky of its diagonal block and a triangular solve of the rows below).
//
// Left-looking rather than multifrontal: the result is written straight into the factor's own
// blocks and the only other memory is one update's dense product per thread (no stack of update
// matrices whose peak can exceed the factor's share of a subtree), and a supernode reads only
// finished descendants and writes only its own block, so disjoint subtrees run on different
// threads with no lock.
#pragma once

#include <cstdint>
#include <vector>

#include "core/base/cancel_token.h"
#include "core/base/status.h"

namespace deform::solver_internal {

// Which descendants update which supernode, derived from the supernodes' rows alone.
struct SupernodalUpdates {
  // Descendant d's rows [begin, end) (counted from its first row) are columns of the target; the
  // update is rows [begin, d's last row] times rows [begin, end) of d's block.
  struct Update {
    int descendant;
    int begin;
    int end;
  };
  // Target s's updates, descendants ascending: updates[offsets[s] .. offsets[s + 1]).
  std::vector<std::int64_t> offsets;
  std::vector<Update> updates;
  // Doubles of the largest update's product (the workspace a thread needs).
  std::int64_t max_product = 0;
};

// The factor being built: the supernodal layout of CholeskyFactor (cholesky_factor.h), its
// blocks zero on entry, and C = P A P^T's lower triangle by columns (column j's rows, all >= j,
// ascending, and their values).
struct SupernodalNumericInput {
  int size = 0;
  int num_supernodes = 0;
  const int* supernode_columns = nullptr;
  const std::int64_t* row_pointers = nullptr;
  const std::int64_t* value_pointers = nullptr;
  const int* row_indices = nullptr;
  const std::int64_t* lower_pointers = nullptr;
  const int* lower_rows = nullptr;
  const double* lower_values = nullptr;
  const SupernodalUpdates* updates = nullptr;
  double* values = nullptr;
};

// Fills `rows` (row_indices of the layout, sized by `row_pointers`) with every supernode's rows:
// its own columns, then the rows below them ascending: the union of C's lower entries in its
// columns
// (`lower_pointers`, `lower_rows`) and of its children's rows below it. That union is the pattern
// of its last column (symbolic_cholesky.cc, SupernodeColumns), so it fills `row_pointers` exactly.
void SupernodeRows(int size, const std::vector<int>& supernode_columns,
                   const std::vector<std::int64_t>& row_pointers,
                   const std::vector<std::int64_t>& lower_pointers,
                   const std::vector<int>& lower_rows, int* rows);

// The updates of every supernode (SupernodalUpdates) from the filled layout.
SupernodalUpdates PlanSupernodalUpdates(int size, const std::vector<int>& supernode_columns,
                                        const std::vector<std::int64_t>& row_pointers,
                                        const std::vector<int>& row_indices);

// Per-thread scratch of FactorizeSupernodes: sized on first use, reused after.
struct SupernodalWorkspace {
  std::vector<std::int64_t> position;  // row -> the current supernode's block row
  std::vector<double> product;
};

// The outcome of FactorizeSupernodes: OK, cancelled, or the first column (of the factor's order)
// whose pivot was not positive and finite, with the pivot.
struct SupernodalResult {
  Status status;
  int failed_column = -1;
};

// Factorizes supernodes[0 .. count) in that order (ascending; every descendant of each one is
// factorized before it, by an earlier call or earlier in the list). Reads the descendants' blocks,
// writes only the listed supernodes' blocks. `cancel` (may be null) is checked before every
// supernode; once cancelled it returns FAILED_PRECONDITION "cancelled during the numeric
// factorization". A non-positive pivot stops it with INTERNAL naming that column.
SupernodalResult FactorizeSupernodes(const SupernodalNumericInput& input, const int* supernodes,
                                     int count, SupernodalWorkspace* workspace,
                                     const CancelToken* cancel);

}  // namespace deform::solver_internal
