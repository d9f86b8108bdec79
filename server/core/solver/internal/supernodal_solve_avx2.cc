// The triangular passes compiled with -mavx2 -mfma (see CMakeLists.txt); called only after the CPU
// has been checked for both.
#include "supernodal_solve_impl.h"

namespace deform {

void Solve3Avx2Fma(const SupernodalFactorView& factor, const double* b, double* x, double* work) {
  Solve3Impl(factor, b, x, work);
}

void SolveManyAvx2Fma(const SupernodalFactorView& factor, const double* b, double* x, int columns,
                      double* work) {
  SolveManyImpl(factor, b, x, columns, work);
}

void SolveFramesAvx2Fma(const SupernodalFactorView& factor, const double* const* b,
                        double* const* x, int frames, double* work) {
  SolveFramesImpl(factor, b, x, frames, work);
}

void ForwardListAvx2Fma(const SupernodalFactorView& factor, const int* supernodes, int count,
                        double* y, double* planar_buffer) {
  ForwardListImpl(factor, supernodes, count, y, planar_buffer);
}

void BackwardListAvx2Fma(const SupernodalFactorView& factor, const int* supernodes, int count,
                         double* y, double* planar_buffer) {
  BackwardListImpl(factor, supernodes, count, y, planar_buffer);
}

}  // namespace deform
