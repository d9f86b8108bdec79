// Reading and writing skeletons: TGF (libigl's) and the project's JSON description.
// No input crashes a reader: malformed content yields INVALID_ARGUMENT naming the problem. Content
// in a format that is not a skeleton file is named as such (BVH motion capture, a glTF rig), by
// every reader, rather than reported as a parse error of the format that was asked for.
#pragma once

#include <string>
#include <string_view>

#include "core/base/status.h"
#include "core/geometry/skeleton.h"

namespace deform {

enum class SkeletonFormat { kTgf, kJson };

// The message (INVALID_ARGUMENT) for BVH content.
inline constexpr char kBvhNotSupported[] =
    "BVH motion capture is not a supported skeleton format (use TGF, the project's JSON, or a "
    "skinned glTF)";

// The format of skeleton bytes, told by their content: TGF starts with a joint line (a number),
// JSON with '{'. INVALID_ARGUMENT for BVH ("HIERARCHY", kBvhNotSupported), a glTF (binary, or JSON
// with "asset"; glTF rigs are read by ReadGltf, core/io/rig_import.h) and anything else, naming
// what was found.
StatusOr<SkeletonFormat> SkeletonFormatFromBytes(std::string_view bytes);

// TGF (format in the shared data README): joint lines "index x y z [extra...]", '#', bone lines
// "a b [flags...]" with 1-based joints, '#'. Joints are named "joint<0-based index>" and have no
// degrees of freedom (poses address them by rest-frame axes x/y/z).
StatusOr<Skeleton> ParseTgf(std::string_view text);

// The project's JSON description:
//   { "joints": [ { "name": "knee", "position": [x, y, z],
//                   "dofs": [ { "name": "flexion", "axis": [1, 0, 0],
//                               "min": -10, "max": 150 }, ... ] }, ... ],
//     "bones": [ ["hip", "knee"], ["knee", "ankle"] ] }
// Bones name their head then tail joint (names or 0-based indices). A bone may instead be an
// object { "head": ..., "tail": ..., "parent": 3 } whose "parent" (a 0-based bone index; -1 or
// null derives it) makes it a child of that bone even where that bone's tail is not its head
// (Skeleton::Create with parents: game-engine rigs whose thighs hang off the pelvis bone).
// Keys other than these (top-level "joints" and "bones"; a joint's "name", "position", "dofs"; a
// dof's "name", "axis", "min", "max"; a bone object's "head", "tail", "parent") are refused by
// name rather than ignored. SkeletonToJson writes the object form for explicit parents only.
StatusOr<Skeleton> ParseSkeletonJson(std::string_view text);
std::string SkeletonToJson(const Skeleton& skeleton);

// ParseTgf or ParseSkeletonJson.
StatusOr<Skeleton> ParseSkeleton(std::string_view bytes, SkeletonFormat format);

// Reads a file: ".tgf" is TGF, ".json" JSON, any other name is told by its content
// (SkeletonFormatFromBytes); BVH and glTF content is refused whatever the name. NOT_FOUND if the
// file cannot be opened; errors carry the path.
StatusOr<Skeleton> ReadSkeletonFile(const std::string& path);

}  // namespace deform
