#include "core/geometry/triangle_bvh.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

#include "core/io/phantom.h"

namespace deform {
namespace {

// A closed octahedron of "radius" 1 around the origin.
TriangleMesh Octahedron() {
  TriangleMesh mesh;
  mesh.vertices.resize(6, 3);
  mesh.vertices << 1, 0, 0, -1, 0, 0, 0, 1, 0, 0, -1, 0, 0, 0, 1, 0, 0, -1;
  mesh.triangles.resize(8, 3);
  mesh.triangles << 0, 2, 4, 2, 1, 4, 1, 3, 4, 3, 0, 4, 2, 0, 5, 1, 2, 5, 3, 1, 5, 0, 3, 5;
  return mesh;
}

TEST(TriangleBvh, SegmentsCrossTheSurfaceOnlyWhereTheyLeaveIt) {
  const TriangleBvh bvh(Octahedron());
  EXPECT_TRUE(bvh.SegmentCrossesSurface({0, 0, 0}, {2, 0.1, 0.1}, -1, 1e-9));
  EXPECT_FALSE(bvh.SegmentCrossesSurface({0, 0, 0}, {0.2, 0.1, 0.1}, -1, 1e-9));
  EXPECT_FALSE(bvh.SegmentCrossesSurface({3, 0, 0}, {3, 2, 0}, -1, 1e-9));
  // From a corner inward: the triangles at that corner are skipped, nothing else is crossed.
  EXPECT_FALSE(bvh.SegmentCrossesSurface({1, 0, 0}, {0, 0, 0}, 0, 1e-9));
  // From a corner out through the opposite side.
  EXPECT_TRUE(bvh.SegmentCrossesSurface({1, 0, 0}, {-2, 0.05, 0.05}, 0, 1e-9));
}

TEST(TriangleBvh, ContainsAndCountsCrossings) {
  const TriangleBvh bvh(Octahedron());
  EXPECT_TRUE(bvh.Contains({0.1, 0.2, -0.1}));
  EXPECT_FALSE(bvh.Contains({0.6, 0.6, 0.6}));
  EXPECT_FALSE(bvh.Contains({5, 0, 0}));
  EXPECT_EQ(bvh.CountRayCrossings({-5, 0.1, 0.05}, {1, 0, 0}), 2);
  EXPECT_EQ(bvh.CountRayCrossings({0, 0.1, 0.05}, {1, 0, 0}), 1);
}

TEST(TriangleBvh, DistanceToSurfaceMatchesBruteForceOnThePhantom) {
  auto phantom = MakeKneePhantom(2000);
  ASSERT_TRUE(phantom.ok());
  const TriangleMesh& mesh = phantom->mesh;
  const TriangleBvh bvh(mesh);
  std::mt19937 random(7);
  std::uniform_real_distribution<double> coordinate(-6, 12);
  for (int sample = 0; sample < 40; ++sample) {
    const Eigen::Vector3d p(coordinate(random) * 0.3, coordinate(random), coordinate(random) * 0.3);
    // Brute force over the vertices bounds the true distance from above; dense sampling of the
    // phantom makes it close: the BVH's exact distance is never larger, and not much smaller.
    double nearest_vertex = std::numeric_limits<double>::infinity();
    for (int i = 0; i < mesh.num_vertices(); ++i) {
      nearest_vertex = std::min(nearest_vertex, (mesh.vertices.row(i).transpose() - p).norm());
    }
    const double distance = bvh.DistanceToSurface(p);
    EXPECT_LE(distance, nearest_vertex + 1e-12);
    EXPECT_GT(distance, nearest_vertex - 0.5);  // the phantom's edges are about 0.3 long
  }
  // The phantom is closed: its joints lie inside, a point far to the side does not.
  for (const Joint& joint : phantom->skeleton.joints()) {
    EXPECT_TRUE(bvh.Contains(joint.rest_position)) << joint.name;
  }
  EXPECT_FALSE(bvh.Contains({20, 4, 0}));
}

}  // namespace
}  // namespace deform
