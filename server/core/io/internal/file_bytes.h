// Internal to the io layer: reading a whole file into memory for the readers that parse bytes.
#pragma once

#include <string>

#include "core/base/status.h"

namespace deform::io_internal {

// The file's bytes. NOT_FOUND if it cannot be opened, INVALID_ARGUMENT for a directory,
// RESOURCE_EXHAUSTED if it does not fit in memory; messages name the path and `what` ("weights
// file").
StatusOr<std::string> ReadFileBytes(const std::string& path, const char* what);

}  // namespace deform::io_internal
