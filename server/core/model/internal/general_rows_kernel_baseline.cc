// The right-hand side's general-row kernels, any CPU the project builds for: two doubles a vector
// (see CMakeLists.txt).
#include "general_rows_kernel_impl.h"

namespace deform {

// Declared (and picked) in general_rows.cc.
extern const GeneralRowsKernel kBaselineGeneralRowsKernel;
const GeneralRowsKernel kBaselineGeneralRowsKernel = {&RotateSlotsImpl, &MultiplyPacksImpl,
                                                      &MultiplyLongRowsImpl, &MultiplyRigidRowsImpl,
                                                      &AddAnchorsImpl};

}  // namespace deform
