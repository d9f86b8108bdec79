// Reading and writing skeletons: TGF (libigl's) and the project's JSON description.
// No input crashes a reader: malformed content yields INVALID_ARGUMENT naming the problem.
#pragma once

#include <string>
#include <string_view>

#include "core/base/status.h"
#include "core/geometry/skeleton.h"

namespace deform {

// TGF (format in the shared data README): joint lines "index x y z [extra...]", '#', bone lines
// "a b [flags...]" with 1-based joints, '#'. Joints are named "joint<0-based index>" and have no
// degrees of freedom (poses address them by rest-frame axes x/y/z).
StatusOr<Skeleton> ParseTgf(std::string_view text);

// The project's JSON description:
//   { "joints": [ { "name": "knee", "position": [x, y, z],
//                   "dofs": [ { "name": "flexion", "axis": [1, 0, 0],
//                               "min": -10, "max": 150 }, ... ] }, ... ],
//     "bones": [ ["hip", "knee"], ["knee", "ankle"] ] }
// Bones name their head then tail joint (names or 0-based indices).
StatusOr<Skeleton> ParseSkeletonJson(std::string_view text);
std::string SkeletonToJson(const Skeleton& skeleton);

// Reads a file; ".tgf" is TGF, anything else is parsed as JSON.
StatusOr<Skeleton> ReadSkeletonFile(const std::string& path);

}  // namespace deform
