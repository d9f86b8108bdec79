// The edge weights of the Laplacian rows L' (laplacian_system.h): uniform, the mesh's cotangent
// weights, or the cotangent weights of its intrinsic Delaunay triangulation (intrinsic_delaunay.h).
#pragma once

#include <vector>

#include "core/geometry/mesh.h"
#include "core/geometry/mesh_topology.h"
#include "core/model/model_options.h"

namespace deform {

// Per vertex i the weights w_ij of its row: neighbours[offsets[i] .. offsets[i + 1]) ascending,
// without duplicates or i itself, with weights[p] (the sum over every edge joining the two, where
// an intrinsic triangulation has parallel edges). Rows are not symmetric where a row fell back to
// uniform weights.
struct WeightedAdjacency {
  std::vector<int> offsets;  // n + 1
  std::vector<int> neighbors;
  std::vector<double> weights;

  int degree(int i) const { return offsets[i + 1] - offsets[i]; }
};

// What the weights came to, for reports and tests.
struct LaplacianWeightReport {
  LaplacianWeights kind = LaplacianWeights::kUniform;
  int edges = 0;  // of the triangulation the weights come from
  // Edges of negative weight beyond rounding (below -kDelaunayTolerance): kCotangent's where the
  // angles opposite an edge sum to more than 180 degrees (or one boundary angle is obtuse).
  int negative_edges = 0;
  int clamped_cotangents = 0;  // corners whose cotangent hit kMaxCotangent (slivers)
  // Rows whose weights did not sum to a positive share of their magnitude, given uniform weights
  // over the one-ring instead (kMinRowSumFraction).
  int uniform_rows = 0;
  int flips = 0;  // kIntrinsicCotangent: edges flipped to make the triangulation Delaunay
  // kIntrinsicCotangent: vertex pairs joined by an intrinsic edge that are not mesh neighbours
  // (L' then has entries outside the one-ring).
  int new_neighbor_pairs = 0;
  // kIntrinsicCotangent: edges whose weight was set to 0, negative only by rounding (within
  // kDelaunayTolerance) or on the boundary, whose edges cannot be flipped.
  int zeroed_edges = 0;
};

// A row whose weights sum to at most this fraction of the sum of their magnitudes falls back to
// uniform weights: its entries w_ij / sum_j w_ij would otherwise grow without bound as the sum
// cancels (or change sign).
inline constexpr double kMinRowSumFraction = 1e-3;

// The weights of `kind` for `mesh` with its one-ring `adjacency`:
// - kUniform: 1 on every one-ring edge;
// - kCotangent: (cot a_ij + cot b_ij) / 2 over the angles opposite edge ij (one on the boundary),
//   negative where those angles sum to more than 180 degrees;
// - kIntrinsicCotangent: the same on the intrinsic Delaunay triangulation (FlipToDelaunay), with
//   the edges it could not make non-negative (boundary edges opposite an obtuse angle, rounding)
//   set to 0, so that every weight is non-negative.
// Rows that fail kMinRowSumFraction take uniform weights. `report` may be null.
WeightedAdjacency BuildLaplacianWeights(const TriangleMesh& mesh, const VertexAdjacency& adjacency,
                                        LaplacianWeights kind, LaplacianWeightReport* report);

}  // namespace deform
