#include "core/model/cotangent_weights.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "core/io/phantom.h"
#include "core/model/intrinsic_delaunay.h"
#include "tests/core/model/laplacian_meshes.h"

namespace deform {
namespace {

using test_support::GridMesh;
using test_support::ObtuseQuad;
using test_support::WeightOf;

WeightedAdjacency WeightsOf(const TriangleMesh& mesh, LaplacianWeights kind,
                            LaplacianWeightReport* report) {
  return BuildLaplacianWeights(mesh, BuildVertexAdjacency(mesh.triangles, mesh.num_vertices()),
                               kind, report);
}

TEST(CotangentWeights, AGridOfRightIsoscelesTrianglesGivesTheFivePointStencil) {
  const int cells = 4, side = cells + 1;
  const TriangleMesh mesh = GridMesh(cells);
  for (const LaplacianWeights kind :
       {LaplacianWeights::kCotangent, LaplacianWeights::kIntrinsicCotangent}) {
    SCOPED_TRACE(LaplacianWeightsName(kind));
    LaplacianWeightReport report;
    const WeightedAdjacency weights = WeightsOf(mesh, kind, &report);
    EXPECT_EQ(report.flips, 0);  // right angles opposite the diagonals: Delaunay already
    EXPECT_EQ(report.uniform_rows, 0);
    EXPECT_EQ(report.negative_edges, 0);
    EXPECT_EQ(report.new_neighbor_pairs, 0);
    // An interior vertex: 1 to its four axis neighbours, 0 to its two diagonal ones (the grid's
    // scale does not matter).
    const int i = 2 * side + 2;
    ASSERT_EQ(weights.degree(i), 6);
    for (const int j : {i - 1, i + 1, i - side, i + side})
      EXPECT_NEAR(WeightOf(weights, i, j), 1, 1e-12);
    for (const int j : {i - side - 1, i + side + 1}) EXPECT_NEAR(WeightOf(weights, i, j), 0, 1e-12);
    // A boundary edge has one angle opposite it: half the interior weight.
    EXPECT_NEAR(WeightOf(weights, 1, 2), 0.5, 1e-12);
    EXPECT_NEAR(WeightOf(weights, side, 2 * side), 0.5, 1e-12);
  }
}

TEST(CotangentWeights, AnObtuseQuadIsNegativeExtrinsicallyAndNonNegativeIntrinsically) {
  const TriangleMesh mesh = ObtuseQuad();
  LaplacianWeightReport extrinsic_report;
  const WeightedAdjacency extrinsic =
      WeightsOf(mesh, LaplacianWeights::kCotangent, &extrinsic_report);
  // Both angles opposite a-b have cotangent -0.91 / 0.6.
  EXPECT_NEAR(WeightOf(extrinsic, 0, 1), -0.91 / 0.6, 1e-12);
  EXPECT_NEAR(WeightOf(extrinsic, 0, 2), 0.5 * 2 / 0.6, 1e-12);  // the angle at b: cot = 2 / 0.6
  EXPECT_EQ(extrinsic_report.negative_edges, 1);
  EXPECT_EQ(extrinsic_report.flips, 0);
  EXPECT_EQ(WeightOf(extrinsic, 2, 3), 0);  // c and d are not neighbours

  LaplacianWeightReport intrinsic_report;
  const WeightedAdjacency intrinsic =
      WeightsOf(mesh, LaplacianWeights::kIntrinsicCotangent, &intrinsic_report);
  EXPECT_EQ(intrinsic_report.flips, 1);
  EXPECT_EQ(intrinsic_report.negative_edges, 0);
  EXPECT_EQ(intrinsic_report.zeroed_edges, 0);
  EXPECT_EQ(intrinsic_report.new_neighbor_pairs, 1);
  EXPECT_EQ(*std::min_element(intrinsic.weights.begin(), intrinsic.weights.end()) >= 0, true);
  // a-b is gone; c-d has the angles at a and b opposite it, cotangent 0.91 / 0.6 each.
  EXPECT_EQ(intrinsic.degree(0), 2);
  EXPECT_NEAR(WeightOf(intrinsic, 2, 3), 0.91 / 0.6, 1e-12);
  EXPECT_NEAR(WeightOf(intrinsic, 0, 2), 0.5 * 0.18 / 0.6, 1e-12);  // the angle at d
}

TEST(CotangentWeights, ThePhantomHasNegativeCotangentWeightsAndNoNegativeIntrinsicOnes) {
  auto phantom = MakeKneePhantom(2000);
  ASSERT_TRUE(phantom.ok());
  LaplacianWeightReport extrinsic_report;
  const WeightedAdjacency extrinsic =
      WeightsOf(phantom->mesh, LaplacianWeights::kCotangent, &extrinsic_report);
  EXPECT_GT(extrinsic_report.negative_edges, 0);
  EXPECT_LT(*std::min_element(extrinsic.weights.begin(), extrinsic.weights.end()), 0);
  LaplacianWeightReport intrinsic_report;
  const WeightedAdjacency intrinsic =
      WeightsOf(phantom->mesh, LaplacianWeights::kIntrinsicCotangent, &intrinsic_report);
  EXPECT_GT(intrinsic_report.flips, 0);
  EXPECT_GT(intrinsic_report.new_neighbor_pairs, 0);
  EXPECT_EQ(intrinsic_report.negative_edges, 0);
  EXPECT_GE(*std::min_element(intrinsic.weights.begin(), intrinsic.weights.end()), 0);
  EXPECT_EQ(extrinsic_report.uniform_rows, 0);
  EXPECT_EQ(intrinsic_report.uniform_rows, 0);
  // A flip replaces one edge by another: the edge count stays.
  EXPECT_EQ(intrinsic_report.edges, extrinsic_report.edges);
}

TEST(CotangentWeights, ASliverIsClampedAndARowItCancelsFallsBackToUniform) {
  // Angles of about 0.0057, 179.989 and 0.0057 degrees: every cotangent beyond kMaxCotangent.
  TriangleMesh mesh;
  mesh.vertices.resize(3, 3);
  mesh.vertices << 0, 0, 0, 1, 1e-4, 0, 2, 0, 0;
  mesh.triangles.resize(1, 3);
  mesh.triangles << 0, 1, 2;
  LaplacianWeightReport report;
  const WeightedAdjacency weights = WeightsOf(mesh, LaplacianWeights::kCotangent, &report);
  EXPECT_EQ(report.clamped_cotangents, 3);
  // Vertex 0: edge 0-2 opposite the obtuse corner (-kMaxCotangent / 2), 0-1 opposite a sharp one
  // (+kMaxCotangent / 2); they cancel, so the row is uniform. Vertex 1's row is two sharp angles.
  EXPECT_EQ(report.uniform_rows, 2);
  EXPECT_EQ(WeightOf(weights, 0, 1), 1);
  EXPECT_EQ(WeightOf(weights, 0, 2), 1);
  EXPECT_EQ(WeightOf(weights, 1, 0), kMaxCotangent / 2);
  for (const double w : weights.weights) EXPECT_LE(std::abs(w), kMaxCotangent);
}

TEST(CotangentWeights, UniformWeightsAreOnePerOneRingEdge) {
  const TriangleMesh mesh = ObtuseQuad();
  const VertexAdjacency adjacency = BuildVertexAdjacency(mesh.triangles, mesh.num_vertices());
  LaplacianWeightReport report;
  const WeightedAdjacency weights =
      BuildLaplacianWeights(mesh, adjacency, LaplacianWeights::kUniform, &report);
  EXPECT_EQ(weights.offsets, adjacency.offsets);
  EXPECT_EQ(weights.neighbors, adjacency.neighbors);
  for (const double w : weights.weights) EXPECT_EQ(w, 1.0);
  EXPECT_EQ(report.edges, 5);
}

TEST(LaplacianWeights, NamesRoundTripAndUnknownNamesAreRefused) {
  for (const LaplacianWeights kind : {LaplacianWeights::kUniform, LaplacianWeights::kCotangent,
                                      LaplacianWeights::kIntrinsicCotangent}) {
    auto parsed = LaplacianWeightsFromName(LaplacianWeightsName(kind));
    ASSERT_TRUE(parsed.ok());
    EXPECT_EQ(*parsed, kind);
  }
  auto bad = LaplacianWeightsFromName("cotan");
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.status().message().find("uniform, cotangent or intrinsic"), std::string::npos);
}

}  // namespace
}  // namespace deform
