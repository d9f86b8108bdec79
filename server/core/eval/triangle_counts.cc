#include "core/eval/triangle_counts.h"

#include <Eigen/Geometry>

#include "core/geometry/triangle_bvh.h"

namespace deform {
namespace {

// Twice the triangle's area, as a vector along its normal.
Eigen::Vector3d AreaNormal(const Positions& positions, const Triangles& triangles, int f) {
  const Eigen::Vector3d a = positions.row(triangles(f, 0)).transpose();
  const Eigen::Vector3d b = positions.row(triangles(f, 1)).transpose();
  const Eigen::Vector3d c = positions.row(triangles(f, 2)).transpose();
  return (b - a).cross(c - a);
}

}  // namespace

int CountInvertedTriangles(const Triangles& triangles, const Positions& rest,
                           const Positions& posed, const Positions& reference) {
  constexpr double kCrushedAreaFraction = 1e-12;
  int inverted = 0;
  for (int f = 0; f < triangles.rows(); ++f) {
    const Eigen::Vector3d normal = AreaNormal(posed, triangles, f);
    const double rest_area = AreaNormal(rest, triangles, f).norm();
    if (normal.norm() < kCrushedAreaFraction * rest_area ||
        normal.dot(AreaNormal(reference, triangles, f)) < 0) {
      ++inverted;
    }
  }
  return inverted;
}

int CountSelfIntersections(const Triangles& triangles, const Positions& posed) {
  return TriangleBvh(TriangleMesh{posed, triangles}).CountIntersectingTrianglePairs();
}

}  // namespace deform
