// CHOLMOD (SuiteSparse) as a measured anchor for the numeric factorization: linked only into the
// benchmark, never into deformd, deformctl or the core (its supernodal module is GPL; deformd is
// Apache-2.0), and only where libsuitesparse-dev is installed (scripts/packages/bench.txt).
#pragma once

#include <Eigen/SparseCore>
#include <memory>
#include <vector>

namespace deform::bench {

// One matrix analysed by CHOLMOD with a given permutation, ready to be factorized again and again.
class CholmodAnchor {
 public:
  // Whether this build has CHOLMOD (false: Create always returns null).
  static bool Available();
  // Analyses `a` (square, symmetric, both triangles stored; CHOLMOD reads its upper triangle)
  // with the user permutation `permutation` (permutation[new] = old, as SymbolicCholesky's),
  // without a postorder of its own, in supernodal mode. Null when CHOLMOD is absent or fails.
  static std::unique_ptr<CholmodAnchor> Create(const Eigen::SparseMatrix<double>& a,
                                               const std::vector<int>& permutation);
  virtual ~CholmodAnchor() = default;

  // One numeric factorization (cholmod_factorize) with `threads` BLAS threads: its seconds, or a
  // negative number when it fails. The thread count is set through openblas_set_num_threads,
  // found at run time (Debian's CHOLMOD calls whichever libblas.so.3 is installed; the reference
  // BLAS runs on one thread whatever is asked).
  virtual double Factorize(int threads) = 0;
  // OpenBLAS's thread count after the last Factorize; 0 when libblas.so.3 is not OpenBLAS.
  virtual int blas_threads() const = 0;
  virtual double analyze_seconds() const = 0;
  virtual bool supernodal() const = 0;
  virtual double factor_nonzeros() const = 0;
};

}  // namespace deform::bench
