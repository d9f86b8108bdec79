#include "core/constraints/tools.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "core/base/tool_spec.h"

namespace deform {
namespace {

bool Finite(const Eigen::Vector3d& v) { return v.allFinite(); }

// The distance from `x` to the box [lower, upper] (0 inside).
double BoxDistance(const Eigen::Vector3d& x, const Eigen::Vector3d& lower,
                   const Eigen::Vector3d& upper) {
  return (x.cwiseMax(lower).cwiseMin(upper) - x).norm();
}

}  // namespace

bool ToolSet::Add(const Tool& tool) {
  if (count >= kMaxTools) return false;
  tools[count++] = tool;
  return true;
}

StatusOr<Tool> ParseToolSpec(std::string_view text) {
  DEFORM_ASSIGN_OR_RETURN(const ToolSpec spec, ParseToolSpecText(text));
  Tool tool;
  tool.shape = spec.capsule ? Tool::Shape::kCapsule : Tool::Shape::kSphere;
  tool.a = Eigen::Vector3d(spec.a[0], spec.a[1], spec.a[2]);
  tool.b = Eigen::Vector3d(spec.b[0], spec.b[1], spec.b[2]);
  tool.radius = spec.radius;
  return tool;
}

Status ValidateTool(const Tool& tool, int index, const Eigen::Vector3d& lower,
                    const Eigen::Vector3d& upper) {
  const std::string name = "tool " + std::to_string(index);
  const double diagonal = (upper - lower).norm();
  const bool capsule = tool.shape == Tool::Shape::kCapsule;
  if (!Finite(tool.a) || (capsule && !Finite(tool.b)) || !std::isfinite(tool.radius)) {
    return Status::InvalidArgument(name + ": coordinates and radius must be finite");
  }
  if (!(tool.radius > 0) || tool.radius > kMaxToolRadius * diagonal) {
    return Status::InvalidArgument(
        name + ": radius must be in (0, " + std::to_string(kMaxToolRadius) +
        " of the mesh's bounding-box diagonal = " + std::to_string(kMaxToolRadius * diagonal) +
        "]");
  }
  const double reach = kMaxToolReach * diagonal;
  if (BoxDistance(tool.a, lower, upper) > reach ||
      (capsule && BoxDistance(tool.b, lower, upper) > reach)) {
    return Status::InvalidArgument(name + ": lies farther than " + std::to_string(kMaxToolReach) +
                                   " bounding-box diagonals from the mesh");
  }
  return Status::Ok();
}

Status ValidateToolSet(const ToolSet& tools, const Eigen::Vector3d& lower,
                       const Eigen::Vector3d& upper) {
  if (tools.count < 0 || tools.count > ToolSet::kMaxTools) {
    return Status::InvalidArgument("at most " + std::to_string(ToolSet::kMaxTools) +
                                   " tools a frame");
  }
  for (int t = 0; t < tools.count; ++t) {
    Status status = ValidateTool(tools.tools[t], t, lower, upper);
    if (!status.ok()) return status;
  }
  return Status::Ok();
}

bool ToolPenetration(const Tool& tool, const Eigen::Vector3d& x, BonePenetration* out) {
  // The nearest point of the tool's axis: its centre, or the segment's nearest point.
  Eigen::Vector3d axis_point = tool.a;
  Eigen::Vector3d fallback = Eigen::Vector3d::UnitZ();
  if (tool.shape == Tool::Shape::kCapsule) {
    const Eigen::Vector3d segment = tool.b - tool.a;
    const double length2 = segment.squaredNorm();
    const double t = length2 > 0 ? std::clamp((x - tool.a).dot(segment) / length2, 0.0, 1.0) : 0.0;
    axis_point = tool.a + t * segment;
    // On the axis any direction normal to it is outward: take one.
    if (length2 > 0) {
      const Eigen::Vector3d d = segment / std::sqrt(length2);
      fallback = std::abs(d.x()) < 0.9 ? d.cross(Eigen::Vector3d::UnitX()).normalized()
                                       : d.cross(Eigen::Vector3d::UnitY()).normalized();
    }
  }
  const Eigen::Vector3d offset = x - axis_point;
  const double distance = offset.norm();
  if (!(distance < tool.radius)) return false;
  const Eigen::Vector3d normal =
      distance > 1e-12 * tool.radius ? Eigen::Vector3d(offset / distance) : fallback;
  out->depth = tool.radius - distance;
  out->normal = normal;
  out->surface_point = axis_point + tool.radius * normal;
  return true;
}

bool DeepestToolPenetration(const ToolSet& tools, int vertex, const double* xyz,
                            BonePenetration* out) {
  const Eigen::Vector3d x(xyz[3 * vertex], xyz[3 * vertex + 1], xyz[3 * vertex + 2]);
  bool inside = false;
  for (int t = 0; t < tools.count; ++t) {
    BonePenetration found;
    if (ToolPenetration(tools.tools[t], x, &found) && (!inside || found.depth > out->depth)) {
      *out = found;
      out->vertex = vertex;
      out->surface = t;
      inside = true;
    }
  }
  return inside;
}

int FindToolPenetrations(const ToolSet& tools, const double* xyz, int num_vertices,
                         BonePenetration* out, int capacity, PenetrationSummary* summary,
                         const char* skip) {
  *summary = {};
  if (tools.empty()) return 0;
  int written = 0;
  // A min-heap on depth keeps the deepest `capacity` (no allocation: it lives in `out`).
  auto shallower = [](const BonePenetration& a, const BonePenetration& b) {
    return a.depth > b.depth;
  };
  for (int i = 0; i < num_vertices; ++i) {
    BonePenetration found;
    if (!DeepestToolPenetration(tools, i, xyz, &found)) continue;
    ++summary->vertices;
    summary->max_depth = std::max(summary->max_depth, found.depth);
    if (skip != nullptr && skip[i]) continue;
    if (written < capacity) {
      out[written++] = found;
      std::push_heap(out, out + written, shallower);
    } else if (capacity > 0 && found.depth > out[0].depth) {
      std::pop_heap(out, out + written, shallower);
      out[written - 1] = found;
      std::push_heap(out, out + written, shallower);
    }
  }
  std::sort_heap(out, out + written, shallower);
  return written;
}

}  // namespace deform
