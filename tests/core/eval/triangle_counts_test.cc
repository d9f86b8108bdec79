// The quality report's counts on hand-made meshes: crossing triangles, a closed sphere, a flipped
// triangle.
#include "core/eval/triangle_counts.h"

#include <gtest/gtest.h>

#include <cmath>

namespace deform {
namespace {

// A closed UV sphere of radius 1: `rings` bands of latitude, `segments` of longitude.
TriangleMesh Sphere(int rings, int segments) {
  TriangleMesh mesh;
  const int n = 2 + (rings - 1) * segments;
  mesh.vertices.resize(n, 3);
  mesh.vertices.row(0) << 0, 0, 1;
  mesh.vertices.row(n - 1) << 0, 0, -1;
  for (int r = 1; r < rings; ++r) {
    const double theta = M_PI * r / rings;
    for (int s = 0; s < segments; ++s) {
      const double phi = 2 * M_PI * s / segments;
      mesh.vertices.row(1 + (r - 1) * segments + s) << std::sin(theta) * std::cos(phi),
          std::sin(theta) * std::sin(phi), std::cos(theta);
    }
  }
  auto ring_vertex = [&](int r, int s) { return 1 + (r - 1) * segments + (s % segments); };
  std::vector<Eigen::Vector3i> faces;
  for (int s = 0; s < segments; ++s) {
    faces.emplace_back(0, ring_vertex(1, s), ring_vertex(1, s + 1));
    faces.emplace_back(n - 1, ring_vertex(rings - 1, s + 1), ring_vertex(rings - 1, s));
    for (int r = 1; r + 1 < rings; ++r) {
      faces.emplace_back(ring_vertex(r, s), ring_vertex(r + 1, s), ring_vertex(r + 1, s + 1));
      faces.emplace_back(ring_vertex(r, s), ring_vertex(r + 1, s + 1), ring_vertex(r, s + 1));
    }
  }
  mesh.triangles.resize(static_cast<int>(faces.size()), 3);
  for (int f = 0; f < static_cast<int>(faces.size()); ++f) mesh.triangles.row(f) = faces[f];
  return mesh;
}

TEST(TriangleCounts, TwoCrossingTrianglesCountOne) {
  Positions positions(6, 3);
  // One in the plane z = 0, one in the plane x = 0.2 piercing it.
  positions << 0, 0, 0, 1, 0, 0, 0, 1, 0,  //
      0.2, 0.2, -1, 0.2, 0.2, 1, 0.2, -1, 0;
  Triangles triangles(2, 3);
  triangles << 0, 1, 2, 3, 4, 5;
  EXPECT_EQ(CountSelfIntersections(triangles, positions), 1);
  // Moved apart, they no longer meet.
  positions.col(0).tail(3).array() += 5;
  EXPECT_EQ(CountSelfIntersections(triangles, positions), 0);
}

TEST(TriangleCounts, TrianglesSharingACornerAreNotCounted) {
  Positions positions(5, 3);
  positions << 0, 0, 0, 1, 0, 0, 0, 1, 0, 0.2, 0.2, 1, 0.2, 0.2, -1;
  Triangles triangles(2, 3);
  // The second passes through the first's plane but shares corner 0 with it.
  triangles << 0, 1, 2, 0, 3, 4;
  EXPECT_EQ(CountSelfIntersections(triangles, positions), 0);
}

TEST(TriangleCounts, AClosedSphereCountsNothing) {
  const TriangleMesh sphere = Sphere(24, 48);
  EXPECT_EQ(CountSelfIntersections(sphere.triangles, sphere.vertices), 0);
  EXPECT_EQ(
      CountInvertedTriangles(sphere.triangles, sphere.vertices, sphere.vertices, sphere.vertices),
      0);
  // Squashed flat through itself: the cap pushed through the opposite side intersects.
  Positions squashed = sphere.vertices;
  for (int i = 0; i < squashed.rows(); ++i) {
    if (squashed(i, 2) > 0.5) squashed(i, 2) = -1.5 + squashed(i, 2);
  }
  EXPECT_GT(CountSelfIntersections(sphere.triangles, squashed), 0);
}

TEST(TriangleCounts, AFlippedTriangleIsInverted) {
  const TriangleMesh sphere = Sphere(8, 16);
  Positions posed = sphere.vertices;
  // Mirror one triangle's third corner through the line of the other two: its normal turns over.
  const int f = 40;
  const Eigen::Vector3d a = posed.row(sphere.triangles(f, 0)).transpose();
  const Eigen::Vector3d b = posed.row(sphere.triangles(f, 1)).transpose();
  const Eigen::Vector3d c = posed.row(sphere.triangles(f, 2)).transpose();
  const Eigen::Vector3d direction = (b - a).normalized();
  const Eigen::Vector3d foot = a + direction * direction.dot(c - a);
  Triangles one = sphere.triangles.row(f);
  Positions flipped = posed;
  flipped.row(sphere.triangles(f, 2)) = (2 * foot - c).transpose();
  EXPECT_EQ(CountInvertedTriangles(one, sphere.vertices, flipped, posed), 1);
  EXPECT_EQ(CountInvertedTriangles(one, sphere.vertices, posed, posed), 0);
  // Crushed to a line: inverted too, whatever the reference.
  Positions crushed = posed;
  crushed.row(sphere.triangles(f, 2)) = foot.transpose();
  EXPECT_EQ(CountInvertedTriangles(one, sphere.vertices, crushed, crushed), 1);
}

}  // namespace
}  // namespace deform
