// The animation file of deform-animation-bench: one frame per line,
//
//   JOINT:AXIS:DEG[,JOINT:AXIS:DEG...][;root=TX,TY,TZ,AX,AY,AZ,DEG]
//
// the pose syntax of core/base/pose_spec.h ("rest" or nothing before the ';' is the rest pose),
// optionally followed by the root's placement: a translation (TX, TY, TZ, model units) and a
// rotation of DEG degrees about the axis (AX, AY, AZ) through the rest frame's origin, applied
// before the translation (deform.v1.RootTransform). Blank lines and lines whose first non-blank
// character is '#' are ignored; a '#' after a frame's text starts a comment too.
//
// Parsing checks the syntax only; joint and axis names are resolved against a skeleton later
// (ResolveAnimationFrame in animation_pose.h).
#pragma once

#include <array>
#include <string>
#include <string_view>
#include <vector>

#include "core/base/pose_spec.h"
#include "core/base/status.h"

namespace deform::animation {

struct RootPlacement {
  std::array<double, 3> translation = {0, 0, 0};
  std::array<double, 3> axis = {1, 0, 0};  // any length but zero when degrees != 0
  double degrees = 0;
};

struct AnimationFrame {
  int line = 0;           // 1-based line number in the file
  std::string text;       // the line as written (trimmed, comment removed), for reports
  std::string pose_spec;  // the part before ';'
  std::vector<PoseSpecTerm> terms;
  bool has_root = false;
  RootPlacement root;
};

// Parses a whole animation. INVALID_ARGUMENT "line N: ..." naming the first malformed line: a
// pose term that is not JOINT:AXIS:DEG, a ';' part that is not root=... with seven finite numbers,
// a root rotation about a zero axis, or a file with no frame at all.
StatusOr<std::vector<AnimationFrame>> ParseAnimation(std::string_view text);

// Reads and parses a file: NOT_FOUND if it cannot be read, errors prefixed with the path.
StatusOr<std::vector<AnimationFrame>> ReadAnimationFile(const std::string& path);

}  // namespace deform::animation
