// Surgical tools that push the skin: rigid convex shapes (a sphere, a capsule) posed in the
// skin's units and frame, and the query that finds the skin vertices inside them. A frame's
// constraints hold those vertices on the tool's tangent plane, beside the bones' contacts
// (skin_constraints.h), so the skin slides on the tool.
#pragma once

#include <Eigen/Core>
#include <array>
#include <string_view>

#include "core/base/status.h"
#include "core/constraints/bone_contacts.h"

namespace deform {

struct Tool {
  enum class Shape { kSphere, kCapsule };
  Shape shape = Shape::kSphere;
  // A sphere's centre; a capsule's axis runs from `a` to `b` (a sphere ignores `b`). Model units,
  // the skin's frame (the frame's posed skin, root transform included).
  Eigen::Vector3d a = Eigen::Vector3d::Zero();
  Eigen::Vector3d b = Eigen::Vector3d::Zero();
  double radius = 0;  // > 0, model units
};

// The tools of one frame: a fixed array, so that a stream keeps its latest set without
// allocating.
struct ToolSet {
  // At most this many tools a frame: a few instruments at once (a probe, forceps' two jaws, a
  // retractor) is what a surgical scene holds, and the scan for penetrations is linear in it.
  static constexpr int kMaxTools = 4;
  std::array<Tool, kMaxTools> tools{};
  int count = 0;

  bool empty() const { return count == 0; }
  // Adds a tool; false (nothing added) when the set holds kMaxTools already.
  bool Add(const Tool& tool);
};

// A tool's radius is at most this fraction of the skin's bounding-box diagonal, and its ends (a
// sphere's centre, a capsule's two) lie within kMaxToolReach diagonals of the skin's box: a
// bound on client input, far beyond any instrument.
inline constexpr double kMaxToolRadius = 0.5;
inline constexpr double kMaxToolReach = 10;

// INVALID_ARGUMENT naming the tool and the problem: a non-finite coordinate or radius, a radius
// not in (0, kMaxToolRadius * diagonal], an end farther than kMaxToolReach diagonals from the box
// [lower, upper], more than kMaxTools tools.
Status ValidateTool(const Tool& tool, int index, const Eigen::Vector3d& lower,
                    const Eigen::Vector3d& upper);
Status ValidateToolSet(const ToolSet& tools, const Eigen::Vector3d& lower,
                       const Eigen::Vector3d& upper);

// A tool from text (ParseToolSpecText, core/base/tool_spec.h); the values are not validated
// (ValidateTool).
StatusOr<Tool> ParseToolSpec(std::string_view text);

// The penetration of the point `x` into `tool` (depth > 0: the distance to its surface; normal
// outward; surface_point its nearest surface point; `surface` left to the caller), or false.
bool ToolPenetration(const Tool& tool, const Eigen::Vector3d& x, BonePenetration* out);

// The posed skin's vertices 0..num_vertices inside a tool (`xyz`: row i at xyz[3 i]). Writes at
// most `capacity` of them, deepest first when there are more, into `out` (`surface` is the tool's
// index in `tools`) and returns how many it wrote; `summary` counts them all. A vertex inside
// two tools is reported for the deeper. `skip` (per vertex, may be null): vertices not to report
// (they still count in the summary). No allocation.
int FindToolPenetrations(const ToolSet& tools, const double* xyz, int num_vertices,
                         BonePenetration* out, int capacity, PenetrationSummary* summary,
                         const char* skip = nullptr);

// Vertex `vertex`'s deepest penetration into any tool, or false when it is inside none.
bool DeepestToolPenetration(const ToolSet& tools, int vertex, const double* xyz,
                            BonePenetration* out);

}  // namespace deform
