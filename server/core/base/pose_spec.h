// The pose syntax of deformctl, the clients and the tests: "JOINT:AXIS:DEGREES[,JOINT:AXIS:...]",
// e.g. "knee:flexion:90, 0:x:-10". Parsed here without a skeleton; what JOINT and AXIS name is
// resolved against one by ParsePoseSpec (core/geometry/pose.h) or by the server.
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include "core/base/status.h"

namespace deform {

// One term as written: the joint (a name or a 0-based index) and the axis (x, y, z or the name of
// one of the joint's degrees of freedom), both trimmed and non-empty, and a finite angle.
struct PoseSpecTerm {
  std::string joint;
  std::string axis;
  double degrees = 0;
};

// Splits `spec` at commas into terms, each three colon-separated fields with whitespace around
// them ignored. "" or "rest" (with any surrounding whitespace) is the rest pose: no term.
// INVALID_ARGUMENT naming the offending term when a term has not three fields, an empty joint or
// axis, or an angle that is not a finite decimal number (ParseFiniteDouble); an empty term (as
// in "a:x:1,,b:x:2" or a trailing comma) is offending too.
StatusOr<std::vector<PoseSpecTerm>> ParsePoseSpecTerms(std::string_view spec);

}  // namespace deform
