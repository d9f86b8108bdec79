#include "core/solver/symbolic_cholesky.h"

#include <algorithm>
#include <limits>
#include <numeric>
#include <string>
#include <utility>

#include "internal/row_pattern.h"

namespace deform {
namespace {

using ColMajorMatrix = Eigen::SparseMatrix<double, Eigen::ColMajor, int>;

Status CheckDiagonal(const ColMajorMatrix& a) {
  for (int j = 0; j < a.cols(); ++j) {
    bool has_diagonal = false;
    for (ColMajorMatrix::InnerIterator it(a, j); it; ++it) has_diagonal |= it.row() == j;
    if (!has_diagonal) {
      return Status::InvalidArgument("matrix has no diagonal entry in column " + std::to_string(j));
    }
  }
  return Status::Ok();
}

// Column pointers of C's upper triangle: how many of A's entries land on or above C's diagonal
// in each column, `inverse` being the inverse permutation (old -> new).
std::vector<int> UpperColumnPointers(const ColMajorMatrix& a, const std::vector<int>& inverse) {
  const int n = static_cast<int>(a.cols());
  std::vector<int> counts(n + 1, 0);
  for (int j = 0; j < n; ++j) {
    for (ColMajorMatrix::InnerIterator it(a, j); it; ++it) {
      const int r = inverse[it.row()], c = inverse[j];
      if (r <= c) ++counts[c + 1];
    }
  }
  std::vector<int> pointers(n + 1, 0);
  std::partial_sum(counts.begin(), counts.end(), pointers.begin());
  return pointers;
}

// Sorts the rows within each column of C, moving the map from A's entries along.
void SortRowsKeepingMap(const std::vector<int>& column_pointers, std::vector<int>* row_indices,
                        std::vector<int>* a_to_c) {
  std::vector<int> position_of(row_indices->size());
  std::vector<std::pair<int, int>> column;
  for (std::size_t c = 0; c + 1 < column_pointers.size(); ++c) {
    column.clear();
    for (int p = column_pointers[c]; p < column_pointers[c + 1]; ++p) {
      column.emplace_back((*row_indices)[p], p);
    }
    std::sort(column.begin(), column.end());
    for (int q = 0; q < static_cast<int>(column.size()); ++q) {
      const int p = column_pointers[c] + q;
      (*row_indices)[p] = column[q].first;
      position_of[column[q].second] = p;
    }
  }
  for (int& target : *a_to_c) {
    if (target >= 0) target = position_of[target];
  }
}

// Elimination tree of C from its upper triangle (CSparse's cs_etree with path compression).
std::vector<int> EliminationTree(const std::vector<int>& cp, const std::vector<int>& ci) {
  const int n = static_cast<int>(cp.size()) - 1;
  std::vector<int> parent(n, -1), ancestor(n, -1);
  for (int k = 0; k < n; ++k) {
    for (int p = cp[k]; p < cp[k + 1]; ++p) {
      for (int i = ci[p]; i != -1 && i < k;) {
        const int next_i = ancestor[i];
        ancestor[i] = k;
        if (next_i == -1) {
          parent[i] = k;
          break;
        }
        i = next_i;
      }
    }
  }
  return parent;
}

// Non-zeros of each column of L, diagonal included, from the row patterns.
std::vector<std::int64_t> ColumnCounts(const std::vector<int>& cp, const std::vector<int>& ci,
                                       const std::vector<int>& parent) {
  const int n = static_cast<int>(parent.size());
  std::vector<std::int64_t> counts(n, 1);  // the diagonal
  std::vector<int> stack(n), mark(n, -1);
  for (int k = 0; k < n; ++k) {
    const int top = solver_internal::RowPattern(k, cp, ci, parent, &stack, &mark);
    for (int t = top; t < n; ++t) ++counts[stack[t]];
  }
  return counts;
}

// A postorder of the elimination tree (`parent`, -1 for a root): every subtree's columns
// consecutive, each column right after its subtree, a node's children in ascending order of
// `weight` (ties by index), so that the heaviest child comes last, next to its parent. Renumbering
// the columns in this order leaves the factor's fill and its tree's shape unchanged, and puts each
// chain of the tree (a parent following its child) in consecutive columns, where SupernodeColumns
// can merge them. order[k] = the column that comes k-th.
std::vector<int> Postorder(const std::vector<int>& parent,
                           const std::vector<std::int64_t>& weight) {
  const int n = static_cast<int>(parent.size());
  std::vector<int> by_weight(n);
  std::iota(by_weight.begin(), by_weight.end(), 0);
  std::stable_sort(by_weight.begin(), by_weight.end(),
                   [&](int a, int b) { return weight[a] > weight[b]; });
  // Children lists, each in ascending weight (a child pushed later goes in front).
  std::vector<int> first_child(n, -1), next_sibling(n, -1);
  for (const int j : by_weight) {
    if (parent[j] < 0) continue;
    next_sibling[j] = first_child[parent[j]];
    first_child[parent[j]] = j;
  }
  std::vector<int> order, stack;
  order.reserve(n);
  for (auto root = by_weight.rbegin(); root != by_weight.rend(); ++root) {
    if (parent[*root] >= 0) continue;
    stack.push_back(*root);
    while (!stack.empty()) {
      const int top = stack.back();
      const int child = first_child[top];
      if (child < 0) {
        order.push_back(top);
        stack.pop_back();
      } else {
        first_child[top] = next_sibling[child];
        stack.push_back(child);
      }
    }
  }
  return order;
}

// Supernode boundaries, relaxed (CHOLMOD's amalgamation rule and defaults): column j joins j - 1's
// supernode when j is j - 1's parent in the elimination tree and the merged block's explicit zeros
// stay within a share that shrinks as the supernode widens: any share up to 4 columns, 80% up to
// 16, 10% up to 48, 5% beyond, up to 128 columns. A chain's columns nest (each one's pattern below
// itself lies in its parent's), so the block's rows are its columns and the last column's
// pattern, and every member column's entries fall on them (zeros elsewhere). Wider supernodes
// mean fewer, longer inner loops in the triangular passes for a few more bytes.
std::vector<int> SupernodeColumns(const std::vector<int>& parent,
                                  const std::vector<std::int64_t>& column_counts) {
  constexpr int kMaxSupernodeWidth = 128;
  const int n = static_cast<int>(parent.size());
  std::vector<int> first_columns(1, 0);
  double nonzeros = n > 0 ? static_cast<double>(column_counts[0]) : 0;  // of the current supernode
  for (int j = 1; j < n; ++j) {
    const int first = first_columns.back();
    const int width = j - first + 1;  // with j
    bool joins = parent[j - 1] == j && width <= kMaxSupernodeWidth;
    if (joins) {
      // The block of columns first..j: its rows are first..j and column j's pattern below j.
      const double rows = static_cast<double>(j - first) + static_cast<double>(column_counts[j]);
      const double entries = width * rows - width * (width - 1) / 2.0;
      const double zeros = (entries - (nonzeros + static_cast<double>(column_counts[j]))) / entries;
      joins = width <= 4 || (width <= 16 && zeros < 0.8) || (width <= 48 && zeros < 0.1) ||
              zeros < 0.05;
    }
    if (joins) {
      nonzeros += static_cast<double>(column_counts[j]);
    } else {
      first_columns.push_back(j);
      nonzeros = static_cast<double>(column_counts[j]);
    }
  }
  first_columns.push_back(n);
  return first_columns;
}

int WidestSupernode(const std::vector<int>& supernode_columns) {
  int widest = 1;
  for (std::size_t k = 0; k + 1 < supernode_columns.size(); ++k) {
    widest = std::max(widest, supernode_columns[k + 1] - supernode_columns[k]);
  }
  return widest;
}

}  // namespace

StatusOr<std::shared_ptr<const SymbolicCholesky>> SymbolicCholesky::Analyze(const ColMajorMatrix& a,
                                                                            Ordering ordering) {
  if (a.rows() != a.cols()) return Status::InvalidArgument("Cholesky needs a square matrix");
  if (!a.isCompressed()) return Status::InvalidArgument("Cholesky needs a compressed matrix");
  if (ordering == Ordering::kAuto) {
    DEFORM_ASSIGN_OR_RETURN(auto amd, Analyze(a, Ordering::kAmd));
    DEFORM_ASSIGN_OR_RETURN(auto metis, Analyze(a, Ordering::kMetis));
    return amd->factor_nonzeros() < metis->factor_nonzeros() ? amd : metis;
  }
  const int n = static_cast<int>(a.cols());
  auto s = std::make_shared<SymbolicCholesky>();
  s->n_ = n;
  s->ordering_ = ordering;
  DEFORM_ASSIGN_OR_RETURN(const std::vector<int> fill_reducing, FillReducingOrdering(a, ordering));
  s->permutation_ = fill_reducing;
  DEFORM_RETURN_IF_ERROR(s->AnalyzePermutedPattern(a));
  s->elimination_tree_ = EliminationTree(s->c_column_pointers_, s->c_row_indices_);
  std::vector<std::int64_t> column_counts =
      ColumnCounts(s->c_column_pointers_, s->c_row_indices_, s->elimination_tree_);
  if (ordering != Ordering::kNatural) {
    // The ordering followed by a postorder of its elimination tree (as CHOLMOD does): the same
    // fill, with the tree's chains in consecutive columns, so that the relaxed amalgamation below
    // merges them into far fewer, wider supernodes with fewer rows below their diagonal blocks to
    // update. The solves got faster and the numeric factorization stayed alike
    // (bench/RESULTS.md, "Factorization and time to first frame").
    // A postorder is a topological relabelling of the tree, so the renumbered matrix's tree and
    // column counts are the old ones relabelled; only the permuted pattern is rebuilt.
    const std::vector<int> order = Postorder(s->elimination_tree_, column_counts);
    std::vector<int> position_of(n);
    for (int k = 0; k < n; ++k) position_of[order[k]] = k;
    std::vector<int> parent(n);
    std::vector<std::int64_t> counts(n);
    for (int k = 0; k < n; ++k) {
      const int old_parent = s->elimination_tree_[order[k]];
      parent[k] = old_parent < 0 ? -1 : position_of[old_parent];
      counts[k] = column_counts[order[k]];
      s->permutation_[k] = fill_reducing[order[k]];
    }
    s->elimination_tree_ = std::move(parent);
    column_counts = std::move(counts);
    DEFORM_RETURN_IF_ERROR(s->AnalyzePermutedPattern(a));
  }
  s->column_pointers_.assign(n + 1, 0);
  std::partial_sum(column_counts.begin(), column_counts.end(), s->column_pointers_.begin() + 1);
  s->supernode_columns_ = SupernodeColumns(s->elimination_tree_, column_counts);
  s->max_supernode_width_ = WidestSupernode(s->supernode_columns_);
  if (s->column_pointers_[n] > std::numeric_limits<int>::max()) {
    return Status::ResourceExhausted("Cholesky factor would have " +
                                     std::to_string(s->column_pointers_[n]) + " non-zeros");
  }
  return std::shared_ptr<const SymbolicCholesky>(std::move(s));
}

Status SymbolicCholesky::AnalyzePermutedPattern(const ColMajorMatrix& a) {
  const int n = n_;
  inverse_permutation_.assign(n, 0);
  for (int i = 0; i < n; ++i) inverse_permutation_[permutation_[i]] = i;
  const std::vector<int>& inverse = inverse_permutation_;
  a_nonzeros_ = a.nonZeros();
  a_column_pointers_.assign(a.outerIndexPtr(), a.outerIndexPtr() + n + 1);
  a_row_indices_.assign(a.innerIndexPtr(), a.innerIndexPtr() + a.nonZeros());
  DEFORM_RETURN_IF_ERROR(CheckDiagonal(a));
  c_column_pointers_ = UpperColumnPointers(a, inverse);
  c_row_indices_.assign(c_column_pointers_[n], 0);
  a_to_c_.assign(a.nonZeros(), -1);
  std::vector<int> next(c_column_pointers_.begin(), c_column_pointers_.end() - 1);
  for (int j = 0; j < n; ++j) {
    for (int p = a.outerIndexPtr()[j]; p < a.outerIndexPtr()[j + 1]; ++p) {
      const int r = inverse[a.innerIndexPtr()[p]], c = inverse[j];
      if (r > c) continue;
      a_to_c_[p] = next[c];
      c_row_indices_[next[c]++] = r;
    }
  }
  SortRowsKeepingMap(c_column_pointers_, &c_row_indices_, &a_to_c_);
  return Status::Ok();
}

}  // namespace deform
