// The triangular passes for any CPU the project builds for.
#include "supernodal_solve_impl.h"

namespace deform {

void Solve3Baseline(const SupernodalFactorView& factor, const double* b, double* x, double* work) {
  Solve3Impl(factor, b, x, work);
}

void SolveManyBaseline(const SupernodalFactorView& factor, const double* b, double* x, int columns,
                       double* work) {
  SolveManyImpl(factor, b, x, columns, work);
}

}  // namespace deform
