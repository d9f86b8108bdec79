// The pose syntax of deformctl, the clients and the tests: "JOINT:AXIS:DEGREES[,JOINT:AXIS:...]",
// e.g. "knee:flexion:90, 0:x:-10, mixamorig:LeftForeArm:z:60". Parsed here without a skeleton; what
// JOINT and AXIS name is resolved against one by ParsePoseSpec (core/geometry/pose.h) or by the
// server.
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

// Splits `spec` at commas into terms, each JOINT:AXIS:DEGREES with whitespace around the fields
// ignored. The axis and the angle are read from the right (the last two colon-separated fields),
// so a joint name may hold colons: "mixamorig:LeftForeArm:z:60". A joint name in double quotes
// may hold commas and spaces too ("\"left arm, upper\":x:30"; a name cannot hold a double quote);
// commas inside quotes do not split terms. "" or "rest" (with any surrounding whitespace) is the
// rest pose: no term. INVALID_ARGUMENT naming the offending term when a term has fewer than three
// fields (or, with a quoted joint, more), an empty joint or axis, or an angle that is not a finite
// decimal number (ParseFiniteDouble); an empty term (as in "a:x:1,,b:x:2" or a trailing comma) is
// offending too.
StatusOr<std::vector<PoseSpecTerm>> ParsePoseSpecTerms(std::string_view spec);

}  // namespace deform
