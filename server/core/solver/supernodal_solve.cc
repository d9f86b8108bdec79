#include "core/solver/supernodal_solve.h"

namespace deform {

// Defined in supernodal_solve_baseline.cc and, where built, supernodal_solve_avx2.cc.
void Solve3Baseline(const SupernodalFactorView& factor, const double* b, double* x, double* work);
void SolveManyBaseline(const SupernodalFactorView& factor, const double* b, double* x, int columns,
                       double* work);
void SolveFramesBaseline(const SupernodalFactorView& factor, const double* const* b,
                         double* const* x, int frames, double* work);
void ForwardListBaseline(const SupernodalFactorView& factor, const int* supernodes, int count,
                         double* y, double* planar_buffer);
void BackwardListBaseline(const SupernodalFactorView& factor, const int* supernodes, int count,
                          double* y, double* planar_buffer);
#if defined(DEFORM_HAVE_AVX2_KERNEL)
void SolveFramesAvx2Fma(const SupernodalFactorView& factor, const double* const* b,
                        double* const* x, int frames, double* work);
void ForwardListAvx2Fma(const SupernodalFactorView& factor, const int* supernodes, int count,
                        double* y, double* planar_buffer);
void BackwardListAvx2Fma(const SupernodalFactorView& factor, const int* supernodes, int count,
                         double* y, double* planar_buffer);
void Solve3Avx2Fma(const SupernodalFactorView& factor, const double* b, double* x, double* work);
void SolveManyAvx2Fma(const SupernodalFactorView& factor, const double* b, double* x, int columns,
                      double* work);
#endif

const char* SolveKernelName(SolveKernel kernel) {
  switch (kernel) {
    case SolveKernel::kBaseline:
      return "baseline";
    case SolveKernel::kAvx2Fma:
      return "avx2+fma";
  }
  return "unknown";
}

bool SolveKernelAvailable(SolveKernel kernel) {
  switch (kernel) {
    case SolveKernel::kBaseline:
      return true;
    case SolveKernel::kAvx2Fma:
#if defined(DEFORM_HAVE_AVX2_KERNEL)
      // By feature, not by CPU model: GCC's target_clones("arch=...") checks the model and so
      // falls back to the baseline on every CPU newer than the one named.
      return __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma");
#else
      return false;
#endif
  }
  return false;
}

SolveKernel BestSolveKernel() {
  static const SolveKernel best =
      SolveKernelAvailable(SolveKernel::kAvx2Fma) ? SolveKernel::kAvx2Fma : SolveKernel::kBaseline;
  return best;
}

Solve3Function Solve3For(SolveKernel kernel) {
#if defined(DEFORM_HAVE_AVX2_KERNEL)
  if (kernel == SolveKernel::kAvx2Fma) return &Solve3Avx2Fma;
#endif
  (void)kernel;
  return &Solve3Baseline;
}

SolveManyFunction SolveManyFor(SolveKernel kernel) {
#if defined(DEFORM_HAVE_AVX2_KERNEL)
  if (kernel == SolveKernel::kAvx2Fma) return &SolveManyAvx2Fma;
#endif
  (void)kernel;
  return &SolveManyBaseline;
}

SolveFramesFunction SolveFramesFor(SolveKernel kernel) {
#if defined(DEFORM_HAVE_AVX2_KERNEL)
  if (kernel == SolveKernel::kAvx2Fma) return &SolveFramesAvx2Fma;
#endif
  (void)kernel;
  return &SolveFramesBaseline;
}

SupernodeListPass ForwardListFor(SolveKernel kernel) {
#if defined(DEFORM_HAVE_AVX2_KERNEL)
  if (kernel == SolveKernel::kAvx2Fma) return &ForwardListAvx2Fma;
#endif
  (void)kernel;
  return &ForwardListBaseline;
}

SupernodeListPass BackwardListFor(SolveKernel kernel) {
#if defined(DEFORM_HAVE_AVX2_KERNEL)
  if (kernel == SolveKernel::kAvx2Fma) return &BackwardListAvx2Fma;
#endif
  (void)kernel;
  return &BackwardListBaseline;
}

}  // namespace deform
