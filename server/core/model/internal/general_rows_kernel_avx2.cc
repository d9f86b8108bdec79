// The right-hand side's general-row kernels, compiled with -mavx2 -mfma: four doubles a vector,
// hardware gathers (see CMakeLists.txt).
#include "general_rows_kernel_impl.h"

namespace deform {

// Declared (and picked) in general_rows.cc.
extern const GeneralRowsKernel kAvx2FmaGeneralRowsKernel;
const GeneralRowsKernel kAvx2FmaGeneralRowsKernel = {&RotateSlotsImpl, &MultiplyPacksImpl,
                                                     &MultiplyLongRowsImpl, &MultiplyRigidRowsImpl,
                                                     &AddAnchorsImpl};

}  // namespace deform
