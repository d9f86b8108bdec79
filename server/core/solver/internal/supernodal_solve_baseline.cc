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

void SolveFramesBaseline(const SupernodalFactorView& factor, const double* const* b,
                         double* const* x, int frames, double* work) {
  SolveFramesImpl(factor, b, x, frames, work);
}

void ForwardListBaseline(const SupernodalFactorView& factor, const int* supernodes, int count,
                         double* y, double* planar_buffer) {
  ForwardListImpl(factor, supernodes, count, y, planar_buffer);
}

void BackwardListBaseline(const SupernodalFactorView& factor, const int* supernodes, int count,
                          double* y, double* planar_buffer) {
  BackwardListImpl(factor, supernodes, count, y, planar_buffer);
}

}  // namespace deform
