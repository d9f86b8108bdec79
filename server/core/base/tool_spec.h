// The tool syntax of deformctl and the clients: "sphere:X,Y,Z,R" or
// "capsule:X0,Y0,Z0,X1,Y1,Z1,R" (model units). Parsed here without a mesh; the values are checked
// against one by ValidateTool (core/constraints/tools.h) or by the server.
#pragma once

#include <string_view>

#include "core/base/status.h"

namespace deform {

struct ToolSpec {
  bool capsule = false;
  double a[3] = {0, 0, 0};  // a sphere's centre, a capsule's first end
  double b[3] = {0, 0, 0};  // a capsule's second end (a sphere: its centre again)
  double radius = 0;
};

// INVALID_ARGUMENT naming the text for another shape, another count of values, or a value that is
// not a finite decimal number.
StatusOr<ToolSpec> ParseToolSpecText(std::string_view text);

}  // namespace deform
