// The right-hand side's general-row kernels, compiled with -mavx2 -mfma -mavx512f -mavx512vl: eight
// doubles a vector, gathers and scatters (see CMakeLists.txt).
#include "general_rows_kernel_impl.h"

namespace deform {

// Declared (and picked) in general_rows.cc.
extern const GeneralRowsKernel kAvx512GeneralRowsKernel;
const GeneralRowsKernel kAvx512GeneralRowsKernel = {&RotateSlotsImpl, &MultiplyPacksImpl,
                                                    &MultiplyLongRowsImpl, &MultiplyRigidRowsImpl,
                                                    &AddAnchorsImpl};

}  // namespace deform
