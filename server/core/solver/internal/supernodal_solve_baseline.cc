// The triangular passes for any CPU the project builds for.
#include "supernodal_solve_impl.h"

namespace deform {

// Declared (and picked) in supernodal_solve.cc.
extern const SolveKernelFunctions kBaselineSolveKernel;
const SolveKernelFunctions kBaselineSolveKernel = {
    &Solve3Impl,         &SolveManyImpl,        &SolveFramesImpl,     &ForwardListImpl,
    &BackwardListImpl,   kBatchLanes,           &ForwardListManyImpl, &BackwardListManyImpl,
    &SolveBackward3Impl, &SolveBackwardManyImpl};

}  // namespace deform
