#include "core/geometry/skeleton_geometry.h"

#include <algorithm>
#include <limits>

namespace deform {

double ClosestSegmentParameter(const Eigen::Vector3d& p, const Eigen::Vector3d& a,
                               const Eigen::Vector3d& b) {
  const Eigen::Vector3d ab = b - a;
  const double length_squared = ab.squaredNorm();
  if (length_squared <= 0) return 0;
  return std::clamp((p - a).dot(ab) / length_squared, 0.0, 1.0);
}

double PointSegmentDistance(const Eigen::Vector3d& p, const Eigen::Vector3d& a,
                            const Eigen::Vector3d& b) {
  const double t = ClosestSegmentParameter(p, a, b);
  return (p - (a + t * (b - a))).norm();
}

std::vector<NearestBone> NearestBones(const Positions& vertices, const Skeleton& skeleton) {
  std::vector<NearestBone> nearest(vertices.rows());
  for (int i = 0; i < vertices.rows(); ++i) {
    const Eigen::Vector3d p = vertices.row(i).transpose();
    NearestBone best;
    best.distance = std::numeric_limits<double>::infinity();
    for (int k = 0; k < skeleton.num_bones(); ++k) {
      const Eigen::Vector3d& a = skeleton.joint(skeleton.bone(k).head_joint).rest_position;
      const Eigen::Vector3d& b = skeleton.joint(skeleton.bone(k).tail_joint).rest_position;
      const double t = ClosestSegmentParameter(p, a, b);
      const double d = (p - (a + t * (b - a))).norm();
      if (d < best.distance) best = {k, t, d};
    }
    nearest[i] = best;
  }
  return nearest;
}

}  // namespace deform
