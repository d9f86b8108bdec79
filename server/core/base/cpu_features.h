#pragma once

// What the CPU this process runs on can do, for the kernels compiled twice (for any x86-64 and
// with `__attribute__((target("avx2,fma")))`) that pick one at run time. By feature, not by CPU
// model: a check by model falls back to the baseline on every CPU newer than the one named.
// Answered once and cached; false on other architectures and compilers.

namespace deform {

bool CpuHasAvx2();
bool CpuHasAvx2Fma();

}  // namespace deform
