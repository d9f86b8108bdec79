// deform_version() (deform_c.h): the project's version, from the one home every program's
// --version reads (core/base/build_info.h).
#include "core/base/build_info.h"
#include "deform_c.h"

extern "C" {

const char* deform_version(void) { return deform::BuildVersion().data(); }

}  // extern "C"
