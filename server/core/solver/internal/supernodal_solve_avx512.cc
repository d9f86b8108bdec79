// The triangular passes compiled with -mavx2 -mfma -mavx512f -mavx512vl (see CMakeLists.txt): the
// batched passes eight doubles wide, the three-column passes as the AVX2 variant's with thirty-two
// registers. Called only after the CPU (and the operating system) has been checked for all four.
#include "supernodal_solve_impl.h"

namespace deform {

// Declared (and picked) in supernodal_solve.cc.
extern const SolveKernelFunctions kAvx512SolveKernel;
const SolveKernelFunctions kAvx512SolveKernel = {
    &Solve3Impl,         &SolveManyImpl,        &SolveFramesImpl,     &ForwardListImpl,
    &BackwardListImpl,   kBatchLanes,           &ForwardListManyImpl, &BackwardListManyImpl,
    &SolveBackward3Impl, &SolveBackwardManyImpl};

}  // namespace deform
