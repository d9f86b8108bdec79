#include "core/base/cpu_features.h"

namespace deform {
namespace {

#if defined(__x86_64__) && defined(__GNUC__)
bool Supports(bool fma) {
  __builtin_cpu_init();
  return __builtin_cpu_supports("avx2") && (!fma || __builtin_cpu_supports("fma"));
}
#else
bool Supports(bool) { return false; }
#endif

}  // namespace

bool CpuHasAvx2() {
  static const bool has = Supports(false);
  return has;
}

bool CpuHasAvx2Fma() {
  static const bool has = Supports(true);
  return has;
}

}  // namespace deform
