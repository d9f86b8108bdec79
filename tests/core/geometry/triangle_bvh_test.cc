#include "core/geometry/triangle_bvh.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <utility>
#include <vector>

#include "core/io/mesh_io.h"
#include "core/io/phantom.h"
#include "tests/allocation_counter.h"
#include "tests/shared_data.h"

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

// Brute force, independent of the tree's code: the closest point of triangle abc to p by
// projection onto its plane when that falls inside, otherwise the nearest of its three edges.
Eigen::Vector3d BruteClosestOnTriangle(const Eigen::Vector3d& p, const Eigen::Vector3d& a,
                                       const Eigen::Vector3d& b, const Eigen::Vector3d& c) {
  const Eigen::Vector3d n = (b - a).cross(c - a).normalized();
  const Eigen::Vector3d projected = p - (p - a).dot(n) * n;
  const auto inside_edge = [&](const Eigen::Vector3d& u, const Eigen::Vector3d& v) {
    return (v - u).cross(projected - u).dot(n) >= 0;
  };
  if (inside_edge(a, b) && inside_edge(b, c) && inside_edge(c, a)) return projected;
  Eigen::Vector3d best = a;
  for (const auto& [u, v] : {std::pair{a, b}, std::pair{b, c}, std::pair{c, a}}) {
    const double t = std::clamp((p - u).dot(v - u) / (v - u).squaredNorm(), 0.0, 1.0);
    const Eigen::Vector3d on_edge = u + t * (v - u);
    if ((on_edge - p).squaredNorm() < (best - p).squaredNorm()) best = on_edge;
  }
  return best;
}

// Brute force over every triangle, pruned only by each triangle's bounding sphere against the
// nearest vertex's distance (an upper bound): exact, and independent of the tree's code.
class BruteSurface {
 public:
  explicit BruteSurface(const TriangleMesh& mesh) : mesh_(mesh) {
    centres_.resize(mesh.num_triangles());
    radii_.resize(mesh.num_triangles());
    for (int f = 0; f < mesh.num_triangles(); ++f) {
      const Eigen::Vector3d a = mesh.vertices.row(mesh.triangles(f, 0));
      const Eigen::Vector3d b = mesh.vertices.row(mesh.triangles(f, 1));
      const Eigen::Vector3d c = mesh.vertices.row(mesh.triangles(f, 2));
      centres_[f] = (a + b + c) / 3;
      radii_[f] =
          std::max({(a - centres_[f]).norm(), (b - centres_[f]).norm(), (c - centres_[f]).norm()});
    }
  }

  double Distance(const Eigen::Vector3d& p) const {
    double best = std::numeric_limits<double>::infinity();
    for (int i = 0; i < mesh_.num_vertices(); ++i) {
      best = std::min(best, (mesh_.vertices.row(i).transpose() - p).norm());
    }
    for (int f = 0; f < mesh_.num_triangles(); ++f) {
      if ((p - centres_[f]).norm() - radii_[f] > best) continue;  // no point of f is nearer
      const Eigen::Vector3d q = BruteClosestOnTriangle(p, mesh_.vertices.row(mesh_.triangles(f, 0)),
                                                       mesh_.vertices.row(mesh_.triangles(f, 1)),
                                                       mesh_.vertices.row(mesh_.triangles(f, 2)));
      best = std::min(best, (q - p).norm());
    }
    return best;
  }

  // The segment's distance to the surface, to within its length / samples: the smallest
  // distance over points spaced along it.
  double SampledSegmentDistance(const Eigen::Vector3d& from, const Eigen::Vector3d& to,
                                int samples) const {
    double best = std::numeric_limits<double>::infinity();
    for (int s = 0; s <= samples; ++s) {
      best = std::min(best, Distance(from + (to - from) * (double(s) / samples)));
    }
    return best;
  }

 private:
  const TriangleMesh& mesh_;
  std::vector<Eigen::Vector3d> centres_;
  std::vector<double> radii_;
};

// Random points and segments around the mesh's box: the tree's closest pair matches brute force
// (a point exactly; a segment within the sampling's spacing, never above the sampled minimum).
void ExpectClosestPairsMatchBruteForce(const TriangleBvh& bvh, const TriangleMesh& mesh,
                                       int queries, unsigned seed) {
  const Eigen::Vector3d lower = mesh.vertices.colwise().minCoeff().transpose();
  const Eigen::Vector3d upper = mesh.vertices.colwise().maxCoeff().transpose();
  const Eigen::Vector3d size = upper - lower;
  std::mt19937 random(seed);
  std::uniform_real_distribution<double> unit(-0.2, 1.2);
  const auto random_point = [&] {
    return Eigen::Vector3d(
        lower + Eigen::Vector3d(unit(random), unit(random), unit(random)).cwiseProduct(size));
  };
  constexpr int kSamples = 64;
  const BruteSurface brute(mesh);
  for (int q = 0; q < queries; ++q) {
    const Eigen::Vector3d p = random_point();
    const TriangleBvh::SegmentSurfacePoint at_point = bvh.ClosestPointToSegment(p, p);
    EXPECT_NEAR(at_point.distance, brute.Distance(p), 1e-9 * size.norm()) << "query " << q;
    EXPECT_NEAR((at_point.point - p).norm(), at_point.distance, 1e-9 * size.norm());
    const Eigen::Vector3d end = p + 0.15 * (random_point() - p);
    const TriangleBvh::SegmentSurfacePoint at_segment = bvh.ClosestPointToSegment(p, end);
    const double sampled = brute.SampledSegmentDistance(p, end, kSamples);
    const double spacing = (end - p).norm() / kSamples;
    EXPECT_LE(at_segment.distance, sampled + 1e-9 * size.norm()) << "query " << q;
    EXPECT_GE(at_segment.distance, sampled - spacing - 1e-9 * size.norm()) << "query " << q;
    EXPECT_NEAR((at_segment.point - at_segment.segment).norm(), at_segment.distance,
                1e-9 * size.norm());
  }
}

TEST(TriangleBvh, ClosestPointToSegmentMatchesBruteForceOnAGeneratedMesh) {
  const KneePhantom phantom = *MakeKneePhantom(1500);
  const TriangleBvh bvh(phantom.mesh);
  ExpectClosestPairsMatchBruteForce(bvh, phantom.mesh, 60, 7);
}

TEST(TriangleBvh, ClosestPointToSegmentMatchesBruteForceOnTheSharedLeg) {
  DEFORM_REQUIRE_SHARED_FILE(path, "leg/leg_1633.obj");
  const TriangleMesh leg = *ReadMeshFile(path);
  const TriangleBvh bvh(leg);
  ExpectClosestPairsMatchBruteForce(bvh, leg, 60, 11);
}

TEST(TriangleBvh, ASegmentThroughTheSurfaceIsAtDistanceZero) {
  const TriangleBvh bvh(Octahedron());
  const TriangleBvh::SegmentSurfacePoint crossing =
      bvh.ClosestPointToSegment({0.1, 0.1, 0.1}, {2, 0.2, 0.3});
  EXPECT_NEAR(crossing.distance, 0, 1e-12);
  EXPECT_NEAR(crossing.point.lpNorm<1>(), 1, 1e-9);  // on the octahedron |x|+|y|+|z| = 1
}

TEST(TriangleBvh, RefitMatchesATreeBuiltOnTheMovedVerticesWithoutAllocating) {
  DEFORM_REQUIRE_SHARED_FILE(path, "leg/leg_1633.obj");
  const TriangleMesh leg = *ReadMeshFile(path);
  // A twist about the long axis growing along it, and a stretch: every box moves.
  TriangleMesh moved = leg;
  const Eigen::Vector3d lower = leg.vertices.colwise().minCoeff().transpose();
  const Eigen::Vector3d upper = leg.vertices.colwise().maxCoeff().transpose();
  int axis = 0;
  (upper - lower).maxCoeff(&axis);
  const int u = (axis + 1) % 3, w = (axis + 2) % 3;
  for (int v = 0; v < leg.num_vertices(); ++v) {
    const double along = (leg.vertices(v, axis) - lower[axis]) / (upper[axis] - lower[axis]);
    const double angle = 0.8 * along;
    const double x = leg.vertices(v, u), y = leg.vertices(v, w);
    moved.vertices(v, u) = std::cos(angle) * x - std::sin(angle) * y;
    moved.vertices(v, w) = std::sin(angle) * x + std::cos(angle) * y;
    moved.vertices(v, axis) *= 1.3;
  }
  TriangleBvh refitted(leg);
  const long before = test_support::AllocationCount();
  refitted.Refit(moved.vertices.data());
  const TriangleBvh::SegmentSurfacePoint probe =
      refitted.ClosestPointToSegment(Eigen::Vector3d::Zero(), Eigen::Vector3d::Ones());
  EXPECT_EQ(test_support::AllocationCount(), before);
  EXPECT_GE(probe.triangle, 0);
  const TriangleBvh built(moved);
  EXPECT_TRUE(refitted.lower().isApprox(built.lower()));
  EXPECT_TRUE(refitted.upper().isApprox(built.upper()));
  ExpectClosestPairsMatchBruteForce(refitted, moved, 40, 13);
}

}  // namespace
}  // namespace deform
