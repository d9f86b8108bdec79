#include "core/geometry/bone_surface.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <unordered_map>

#include "core/geometry/primitive_surfaces.h"

namespace deform {
namespace {

// The number of edges used by one triangle only (0 for a closed surface).
int CountBoundaryEdges(const Triangles& triangles) {
  std::unordered_map<std::int64_t, int> uses;
  for (int f = 0; f < triangles.rows(); ++f) {
    for (int c = 0; c < 3; ++c) {
      const int a = triangles(f, c), b = triangles(f, (c + 1) % 3);
      uses[(static_cast<std::int64_t>(std::min(a, b)) << 32) | std::max(a, b)]++;
    }
  }
  return static_cast<int>(
      std::count_if(uses.begin(), uses.end(), [](const auto& entry) { return entry.second == 1; }));
}

double DistanceToSegment(const Eigen::Vector3d& p, const Eigen::Vector3d& a,
                         const Eigen::Vector3d& b) {
  const Eigen::Vector3d ab = b - a;
  const double t = std::clamp((p - a).dot(ab) / ab.squaredNorm(), 0.0, 1.0);
  return (p - (a + t * ab)).norm();
}

}  // namespace

Status ValidateBoneSurfaces(const std::vector<BoneSurface>& surfaces, const Skeleton& skeleton,
                            const MeshLimits& mesh_limits, const BoneSurfaceLimits& limits) {
  if (static_cast<int>(surfaces.size()) > limits.max_surfaces) {
    return Status::ResourceExhausted("too many bone surfaces: " + std::to_string(surfaces.size()) +
                                     " (at most " + std::to_string(limits.max_surfaces) + ")");
  }
  std::size_t triangles = 0;
  for (const BoneSurface& surface : surfaces) {
    const std::string which = "bone surface '" + surface.name + "'";
    if (surface.bone < 0 || surface.bone >= skeleton.num_bones()) {
      return Status::InvalidArgument(which + ": bone " + std::to_string(surface.bone) +
                                     " out of range (the skeleton has " +
                                     std::to_string(skeleton.num_bones()) + " bones)");
    }
    if (surface.blend_bone >= 0) {
      if (surface.blend_bone >= skeleton.num_bones() ||
          skeleton.bone(surface.blend_bone).parent_bone != surface.bone) {
        return Status::InvalidArgument(
            which + ": blend bone " + std::to_string(surface.blend_bone) +
            " is not a child bone of bone " + std::to_string(surface.bone));
      }
      if (!(surface.blend >= 0 && surface.blend <= 1)) {
        return Status::InvalidArgument(which + ": blend must be in [0, 1]");
      }
    }
    const Status valid = ValidateMesh(surface.mesh, mesh_limits);
    if (!valid.ok()) return valid.WithContext(which);
    const int open_edges = CountBoundaryEdges(surface.mesh.triangles);
    if (open_edges > 0) {
      return Status::InvalidArgument(which + " is not closed: " + std::to_string(open_edges) +
                                     " edges belong to one triangle only");
    }
    triangles += surface.mesh.num_triangles();
  }
  if (triangles > limits.max_total_triangles) {
    return Status::ResourceExhausted("bone surfaces hold " + std::to_string(triangles) +
                                     " triangles (at most " +
                                     std::to_string(limits.max_total_triangles) + ")");
  }
  return Status::Ok();
}

RigidTransform BoneSurfaceTransform(const BoneSurface& surface, const Skeleton& skeleton,
                                    const std::vector<RigidTransform>& bones) {
  const RigidTransform& carrier = bones[surface.bone];
  if (surface.blend_bone < 0 || surface.blend == 0) return carrier;
  const RigidTransform& child = bones[surface.blend_bone];
  // Turn about the joint the two bones share, which both carry to the same place.
  const Eigen::Vector3d pivot =
      skeleton.joint(skeleton.bone(surface.blend_bone).head_joint).rest_position;
  RigidTransform blended;
  blended.rotation = carrier.rotation.slerp(surface.blend, child.rotation).normalized();
  blended.translation = child.Apply(pivot) - blended.rotation * pivot;
  return blended;
}

std::vector<BoneSurface> MakeCapsuleBoneSurfaces(const TriangleMesh& skin, const Skeleton& skeleton,
                                                 double radius_fraction,
                                                 double min_radius_fraction) {
  const double diagonal = BoundingBoxDiagonal(skin.vertices);
  std::vector<BoneSurface> surfaces;
  for (int k = 0; k < skeleton.num_bones(); ++k) {
    const Bone& bone = skeleton.bone(k);
    const Eigen::Vector3d head = skeleton.joint(bone.head_joint).rest_position;
    const Eigen::Vector3d tail = skeleton.joint(bone.tail_joint).rest_position;
    double nearest = std::numeric_limits<double>::infinity();
    for (int i = 0; i < skin.num_vertices(); ++i) {
      nearest = std::min(nearest, DistanceToSegment(skin.vertices.row(i).transpose(), head, tail));
    }
    double radius = radius_fraction * nearest;
    if (!(radius >= min_radius_fraction * diagonal)) continue;
    const double length = (tail - head).norm();
    const Eigen::Vector3d along = (tail - head) / length;
    TriangleMesh mesh;
    if (length > 4 * radius) {
      // The caps stop one radius short of the joints.
      mesh = MakeCapsule(head + 2 * radius * along, tail - 2 * radius * along, radius);
    } else {
      radius = std::min(radius, 0.25 * length);
      mesh = MakeCapsule(0.5 * (head + tail), 0.5 * (head + tail), radius);
    }
    surfaces.push_back(
        {skeleton.joint(bone.head_joint).name + "-" + skeleton.joint(bone.tail_joint).name, k, -1,
         0, std::move(mesh)});
  }
  return surfaces;
}

}  // namespace deform
