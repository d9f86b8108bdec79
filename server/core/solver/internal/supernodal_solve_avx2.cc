// The triangular passes compiled with -mavx2 -mfma (see CMakeLists.txt); called only after the CPU
// has been checked for both.
#include "supernodal_solve_impl.h"

namespace deform {

// Declared (and picked) in supernodal_solve.cc.
extern const SolveKernelFunctions kAvx2FmaSolveKernel;
const SolveKernelFunctions kAvx2FmaSolveKernel = {
    &Solve3Impl,         &SolveManyImpl,        &SolveFramesImpl,     &ForwardListImpl,
    &BackwardListImpl,   kBatchLanes,           &ForwardListManyImpl, &BackwardListManyImpl,
    &SolveBackward3Impl, &SolveBackwardManyImpl};

}  // namespace deform
