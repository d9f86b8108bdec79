// The supernodal factorization's update product (internal/supernodal_numeric.h): one
// descendant's rows times its rows in the target's columns, transposed. Internal to the solver.
#pragma once

#include <cstdint>

namespace deform::solver_internal {

// c = a b^T: `a` is m by `depth` and `b` is k by `depth`, both row-major with a row stride of
// `depth`; `c` is m by k, row-major with a row stride of k. With AVX2 and FMA where the CPU has
// them (a kernel of its own, compiled for them by a function attribute, so that no template of
// Eigen is compiled twice with different flags), Eigen's dense product otherwise. The same sums
// in the same order for the same arguments, whatever thread calls it.
void UpdateProduct(const double* a, std::int64_t m, const double* b, int k, int depth, double* c);

// Whether UpdateProduct runs the AVX2 and FMA kernel on this CPU.
bool UpdateProductUsesAvx2();

// The portable product (Eigen's), for tests of the AVX2 kernel against it.
void UpdateProductPortable(const double* a, std::int64_t m, const double* b, int k, int depth,
                           double* c);

}  // namespace deform::solver_internal
