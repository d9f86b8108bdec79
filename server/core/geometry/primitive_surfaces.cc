#include "core/geometry/primitive_surfaces.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <vector>

namespace deform {
namespace {

// A surface of revolution about +z: a pole at each end and the rings of `profile` between them,
// (z, radius) from the top down.
TriangleMesh Revolve(double top, double bottom, const std::vector<Eigen::Vector2d>& profile,
                     int segments) {
  const int rings = static_cast<int>(profile.size());
  TriangleMesh mesh;
  mesh.vertices.resize(2 + rings * segments, 3);
  mesh.vertices.row(0) << 0, 0, top;
  for (int r = 0; r < rings; ++r) {
    for (int s = 0; s < segments; ++s) {
      const double phi = 2 * M_PI * s / segments;
      mesh.vertices.row(1 + r * segments + s) << profile[r].y() * std::cos(phi),
          profile[r].y() * std::sin(phi), profile[r].x();
    }
  }
  const int bottom_pole = 1 + rings * segments;
  mesh.vertices.row(bottom_pole) << 0, 0, bottom;
  mesh.triangles.resize(2 * segments * rings, 3);
  auto ring = [&](int r, int s) { return 1 + r * segments + (s % segments); };
  int f = 0;
  for (int s = 0; s < segments; ++s) mesh.triangles.row(f++) << 0, ring(0, s), ring(0, s + 1);
  for (int r = 0; r + 1 < rings; ++r) {
    for (int s = 0; s < segments; ++s) {
      mesh.triangles.row(f++) << ring(r, s), ring(r + 1, s), ring(r + 1, s + 1);
      mesh.triangles.row(f++) << ring(r, s), ring(r + 1, s + 1), ring(r, s + 1);
    }
  }
  for (int s = 0; s < segments; ++s) {
    mesh.triangles.row(f++) << bottom_pole, ring(rings - 1, s + 1), ring(rings - 1, s);
  }
  return mesh;
}

// The rotation taking +z to `direction` (unit).
Eigen::Matrix3d FrameAlong(const Eigen::Vector3d& direction) {
  return Eigen::Quaterniond::FromTwoVectors(Eigen::Vector3d::UnitZ(), direction).toRotationMatrix();
}

}  // namespace

TriangleMesh MakeCapsule(const Eigen::Vector3d& a, const Eigen::Vector3d& b, double radius,
                         int segments, int cap_rings) {
  segments = std::max(segments, 3);
  cap_rings = std::max(cap_rings, 1);
  const double half = 0.5 * (b - a).norm();
  // Rings of the upper cap down to the equator at z = half, then the lower cap's from z = -half.
  std::vector<Eigen::Vector2d> profile;
  for (int r = 1; r <= cap_rings; ++r) {
    const double theta = 0.5 * M_PI * r / cap_rings;
    profile.emplace_back(half + radius * std::cos(theta), radius * std::sin(theta));
  }
  for (int r = cap_rings; r >= 1; --r) {
    const double theta = 0.5 * M_PI * r / cap_rings;
    if (half == 0 && r == cap_rings) continue;  // a sphere has one equator
    profile.emplace_back(-half - radius * std::cos(theta), radius * std::sin(theta));
  }
  TriangleMesh mesh = Revolve(half + radius, -half - radius, profile, segments);
  const Eigen::Matrix3d frame =
      half > 0 ? FrameAlong((b - a).normalized()) : Eigen::Matrix3d::Identity();
  const Eigen::Vector3d middle = 0.5 * (a + b);
  for (int i = 0; i < mesh.num_vertices(); ++i) {
    mesh.vertices.row(i) = (frame * mesh.vertices.row(i).transpose() + middle).transpose();
  }
  return mesh;
}

TriangleMesh MakeEllipsoid(const Eigen::Vector3d& center, const Eigen::Matrix3d& axes, int segments,
                           int rings) {
  segments = std::max(segments, 3);
  rings = std::max(rings, 2);
  std::vector<Eigen::Vector2d> profile;
  for (int r = 1; r < rings; ++r) {
    const double theta = M_PI * r / rings;
    profile.emplace_back(std::cos(theta), std::sin(theta));
  }
  TriangleMesh mesh = Revolve(1, -1, profile, segments);
  for (int i = 0; i < mesh.num_vertices(); ++i) {
    mesh.vertices.row(i) = (axes * mesh.vertices.row(i).transpose() + center).transpose();
  }
  return mesh;
}

}  // namespace deform
