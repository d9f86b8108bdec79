#include "core/solver/supernodal_solve.h"

#include <initializer_list>

namespace deform {

// Defined in supernodal_solve_baseline.cc and, where built, supernodal_solve_avx2.cc.
extern const SolveKernelFunctions kBaselineSolveKernel;
#if defined(DEFORM_HAVE_AVX2_KERNEL)
extern const SolveKernelFunctions kAvx2FmaSolveKernel;
#endif
#if defined(DEFORM_HAVE_AVX512_KERNEL)
extern const SolveKernelFunctions kAvx512SolveKernel;
#endif

const char* SolveKernelName(SolveKernel kernel) {
  switch (kernel) {
    case SolveKernel::kBaseline:
      return "baseline";
    case SolveKernel::kAvx2Fma:
      return "avx2+fma";
    case SolveKernel::kAvx512:
      return "avx512";
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
    case SolveKernel::kAvx512:
#if defined(DEFORM_HAVE_AVX512_KERNEL)
      // libgcc's check includes the operating system's saving of the AVX-512 registers (XCR0).
      return SolveKernelAvailable(SolveKernel::kAvx2Fma) && __builtin_cpu_supports("avx512f") &&
             __builtin_cpu_supports("avx512vl");
#else
      return false;
#endif
  }
  return false;
}

bool ForwardStreamIsNonTemporal() {
#if defined(__x86_64__) || defined(__i386__)
  static const bool amd = [] {
    __builtin_cpu_init();  // may run during static initialization (supernodal_solve_impl.h)
    return __builtin_cpu_is("amd") != 0;
  }();
  return amd;
#else
  return false;
#endif
}

SolveKernel BestSolveKernel() {
  static const SolveKernel best = [] {
    for (const SolveKernel kernel : {SolveKernel::kAvx512, SolveKernel::kAvx2Fma}) {
      if (SolveKernelAvailable(kernel)) return kernel;
    }
    return SolveKernel::kBaseline;
  }();
  return best;
}

const SolveKernelFunctions& SolveKernelFunctionsFor(SolveKernel kernel) {
#if defined(DEFORM_HAVE_AVX2_KERNEL)
  if (kernel == SolveKernel::kAvx2Fma) return kAvx2FmaSolveKernel;
#endif
#if defined(DEFORM_HAVE_AVX512_KERNEL)
  if (kernel == SolveKernel::kAvx512) return kAvx512SolveKernel;
#endif
  (void)kernel;
  return kBaselineSolveKernel;
}

}  // namespace deform
