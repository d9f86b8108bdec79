// Distances between mesh vertices and the skeleton's bone segments.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "core/geometry/mesh.h"
#include "core/geometry/skeleton.h"

namespace deform {

// The closest point of segment [a, b] to p, as the parameter t in [0, 1] (a + t (b - a)).
double ClosestSegmentParameter(const Eigen::Vector3d& p, const Eigen::Vector3d& a,
                               const Eigen::Vector3d& b);
double PointSegmentDistance(const Eigen::Vector3d& p, const Eigen::Vector3d& a,
                            const Eigen::Vector3d& b);

struct NearestBone {
  int bone = -1;
  double parameter = 0;  // t of the closest point on that bone, 0 at the head, 1 at the tail
  double distance = 0;
};

// For every vertex, the nearest bone segment of the skeleton at rest. Ties go to the lower index.
std::vector<NearestBone> NearestBones(const Positions& vertices, const Skeleton& skeleton);

}  // namespace deform
