// A reference for the numeric factorization's tests: the factor of the same permuted matrix by an
// up-looking simplicial Cholesky (Eigen's SimplicialLLT, natural ordering: the algorithm the
// factorization used before it was supernodal), and the difference of two factors.
#pragma once

#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>
#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "core/solver/sparse_cholesky.h"

namespace deform::testing {

// max |L - L_ref| / max |L_ref| over every entry, L being `factor`'s (FactorMatrix) and L_ref the
// up-looking factor of P A P^T with `symbolic`'s permutation. Infinity when the reference fails.
inline double DifferenceFromUpLookingFactor(
    const CholeskyFactor& factor, const SymbolicCholesky& symbolic,
    const Eigen::SparseMatrix<double, Eigen::ColMajor, int>& a) {
  using Matrix = Eigen::SparseMatrix<double, Eigen::ColMajor, int>;
  const std::vector<int>& permutation = symbolic.permutation();  // [new] = old
  Eigen::PermutationMatrix<Eigen::Dynamic, Eigen::Dynamic, int> old_to_new(a.rows());
  for (int k = 0; k < static_cast<int>(permutation.size()); ++k) {
    old_to_new.indices()[permutation[k]] = k;
  }
  const Matrix c = old_to_new * a * old_to_new.transpose();
  Eigen::SimplicialLLT<Matrix, Eigen::Lower, Eigen::NaturalOrdering<int>> reference(c);
  if (reference.info() != Eigen::Success) return std::numeric_limits<double>::infinity();
  const Matrix l_ref = reference.matrixL();
  const Matrix difference = factor.FactorMatrix() - l_ref;
  double largest = 0, largest_difference = 0;
  for (int j = 0; j < l_ref.outerSize(); ++j) {
    for (Matrix::InnerIterator it(l_ref, j); it; ++it)
      largest = std::max(largest, std::abs(it.value()));
    for (Matrix::InnerIterator it(difference, j); it; ++it) {
      largest_difference = std::max(largest_difference, std::abs(it.value()));
    }
  }
  return largest_difference / largest;
}

}  // namespace deform::testing
