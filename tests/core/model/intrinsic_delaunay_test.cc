#include "core/model/intrinsic_delaunay.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "core/geometry/mesh_topology.h"
#include "core/io/phantom.h"
#include "tests/core/model/laplacian_meshes.h"

namespace deform {
namespace {

using test_support::GridMesh;
using test_support::ObtuseQuad;

// Per vertex the sum of its corners' angles, and the total area, from the edge lengths alone:
// what intrinsic flips must keep.
struct Metric {
  std::vector<double> angle_sums;
  double area = 0;
};

Metric MetricOf(const IntrinsicTriangulation& tri) {
  Metric metric;
  metric.angle_sums.assign(tri.num_vertices, 0.0);
  for (int t = 0; t < tri.num_triangles(); ++t) {
    for (int h = 3 * t; h < 3 * t + 3; ++h) {
      // The corner Next(Next(h)) is opposite the side h starts.
      const int g = IntrinsicTriangulation::Next(h), k = IntrinsicTriangulation::Next(g);
      const double a = tri.edge_length[tri.corner_edge[h]];
      const double b = tri.edge_length[tri.corner_edge[g]];
      const double c = tri.edge_length[tri.corner_edge[k]];
      metric.angle_sums[tri.corner_vertex[k]] +=
          std::acos(std::clamp((b * b + c * c - a * a) / (2 * b * c), -1.0, 1.0));
      if (h == 3 * t) {
        const double s = (a + b + c) / 2;
        metric.area += std::sqrt(std::max(0.0, s * (s - a) * (s - b) * (s - c)));
      }
    }
  }
  return metric;
}

// Every flippable edge's two opposite angles sum to at most 180 degrees.
void ExpectDelaunay(const IntrinsicTriangulation& tri) {
  for (int e = 0; e < tri.num_edges(); ++e) {
    if (!tri.edge_flippable[e]) continue;
    ASSERT_GE(tri.CotangentWeight(e), -kDelaunayTolerance) << e;
  }
}

// The phantom with its vertices moved at random by up to a fifth of the shortest edge: obtuse
// triangles everywhere.
TriangleMesh JitteredPhantom() {
  auto phantom = MakeKneePhantom(2000);
  EXPECT_TRUE(phantom.ok());
  TriangleMesh mesh = phantom->mesh;
  const IntrinsicTriangulation tri = TriangulationOfMesh(mesh);
  const double shortest = *std::min_element(tri.edge_length.begin(), tri.edge_length.end());
  std::mt19937 random(3);
  std::uniform_real_distribution<double> offset(-0.2 * shortest, 0.2 * shortest);
  for (int i = 0; i < mesh.num_vertices(); ++i) {
    for (int c = 0; c < 3; ++c) mesh.vertices(i, c) += offset(random);
  }
  return mesh;
}

TEST(IntrinsicDelaunay, TheMeshTriangulationHasTheMeshEdgesAndLengths) {
  const TriangleMesh mesh = GridMesh(3, 0.25);
  const IntrinsicTriangulation tri = TriangulationOfMesh(mesh);
  const VertexAdjacency adjacency = BuildVertexAdjacency(mesh.triangles, mesh.num_vertices());
  EXPECT_EQ(tri.num_edges(), static_cast<int>(adjacency.neighbors.size()) / 2);
  EXPECT_EQ(tri.num_triangles(), mesh.num_triangles());
  int boundary = 0;
  for (int e = 0; e < tri.num_edges(); ++e) {
    const int h = tri.edge_corners[2 * e];
    const int a = tri.corner_vertex[h], b = tri.corner_vertex[IntrinsicTriangulation::Next(h)];
    EXPECT_NEAR(tri.edge_length[e], (mesh.vertices.row(a) - mesh.vertices.row(b)).norm(), 1e-15);
    if (tri.edge_corners[2 * e + 1] < 0) ++boundary;
    EXPECT_EQ(tri.edge_flippable[e] != 0, tri.edge_corners[2 * e + 1] >= 0);
  }
  EXPECT_EQ(boundary, 12);
}

TEST(IntrinsicDelaunay, AnObtuseQuadFlipsToItsOtherDiagonal) {
  for (const bool consistent : {true, false}) {
    SCOPED_TRACE(consistent ? "consistently oriented" : "oriented against each other");
    IntrinsicTriangulation tri = TriangulationOfMesh(ObtuseQuad(consistent));
    EXPECT_EQ(FlipToDelaunay(&tri), 1);
    ExpectDelaunay(tri);
    int diagonal = -1;
    for (int e = 0; e < tri.num_edges(); ++e) {
      if (tri.edge_corners[2 * e + 1] >= 0) diagonal = e;
    }
    ASSERT_GE(diagonal, 0);
    const int h = tri.edge_corners[2 * diagonal];
    const int a = tri.corner_vertex[h], b = tri.corner_vertex[IntrinsicTriangulation::Next(h)];
    EXPECT_EQ(std::min(a, b), 2);
    EXPECT_EQ(std::max(a, b), 3);
    EXPECT_NEAR(tri.edge_length[diagonal], 0.6, 1e-12);
    EXPECT_NEAR(tri.CotangentWeight(diagonal), 0.91 / 0.6, 1e-12);
  }
}

TEST(IntrinsicDelaunay, FlipsKeepEveryVertexsAngleSumAndTheAreaAndEndDelaunay) {
  for (const bool jittered : {false, true}) {
    SCOPED_TRACE(jittered ? "jittered phantom" : "phantom");
    auto phantom = MakeKneePhantom(2000);
    ASSERT_TRUE(phantom.ok());
    const TriangleMesh mesh = jittered ? JitteredPhantom() : phantom->mesh;
    IntrinsicTriangulation tri = TriangulationOfMesh(mesh);
    const Metric before = MetricOf(tri);
    const int edges = tri.num_edges();
    const int flips = FlipToDelaunay(&tri);
    EXPECT_GT(flips, 0);
    EXPECT_LT(flips, 100 * edges);  // ended by itself, not by the guard
    EXPECT_EQ(tri.num_edges(), edges);
    ExpectDelaunay(tri);
    const Metric after = MetricOf(tri);
    EXPECT_NEAR(after.area, before.area, 1e-9 * before.area);
    for (int i = 0; i < tri.num_vertices; ++i) {
      ASSERT_NEAR(after.angle_sums[i], before.angle_sums[i], 1e-9) << "vertex " << i;
    }
    // Each edge's two sides are two distinct corners that name it.
    for (int e = 0; e < tri.num_edges(); ++e) {
      for (int s = 0; s < 2; ++s) {
        const int h = tri.edge_corners[2 * e + s];
        if (h < 0) continue;
        ASSERT_EQ(tri.corner_edge[h], e);
      }
    }
  }
}

TEST(IntrinsicDelaunay, CornerCotangentsFollowTheLawOfCosinesAndAreClamped) {
  bool clamped = false;
  EXPECT_NEAR(CornerCotangent(1, 1, 1, &clamped), 1 / std::sqrt(3.0), 1e-15);
  EXPECT_NEAR(CornerCotangent(5, 3, 4, &clamped), 0, 1e-15);  // the right angle
  EXPECT_NEAR(CornerCotangent(3, 4, 5, &clamped), 4.0 / 3.0, 1e-15);
  EXPECT_FALSE(clamped);
  EXPECT_EQ(CornerCotangent(2, 1, 1, &clamped), -kMaxCotangent);  // flat, 180 degrees
  EXPECT_TRUE(clamped);
  clamped = false;
  EXPECT_EQ(CornerCotangent(1e-9, 1, 1, &clamped), kMaxCotangent);
  EXPECT_TRUE(clamped);
}

}  // namespace
}  // namespace deform
