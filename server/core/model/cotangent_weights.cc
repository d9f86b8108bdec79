#include "core/model/cotangent_weights.h"

#include <algorithm>
#include <cmath>
#include <tuple>

#include "core/model/intrinsic_delaunay.h"

namespace deform {
namespace {

WeightedAdjacency UniformWeights(const VertexAdjacency& adjacency) {
  WeightedAdjacency out;
  out.offsets = adjacency.offsets;
  out.neighbors = adjacency.neighbors;
  out.weights.assign(adjacency.neighbors.size(), 1.0);
  return out;
}

// The weighted adjacency of the triangulation's edges: parallel edges summed, loops (an edge from
// a vertex to itself adds nothing to v_i - sum_j w_ij v_j / sum_j w_ij) left out.
WeightedAdjacency EdgeWeights(const IntrinsicTriangulation& tri, bool intrinsic,
                              LaplacianWeightReport* report) {
  std::vector<std::tuple<int, int, double>> entries;
  entries.reserve(2 * static_cast<std::size_t>(tri.num_edges()));
  for (int e = 0; e < tri.num_edges(); ++e) {
    double w = tri.CotangentWeight(e, &report->clamped_cotangents);
    if (intrinsic && w < 0) {
      w = 0;
      ++report->zeroed_edges;
    }
    if (w < -kDelaunayTolerance) ++report->negative_edges;
    const int h = tri.edge_corners[2 * e];
    const int a = tri.corner_vertex[h], b = tri.corner_vertex[IntrinsicTriangulation::Next(h)];
    if (a == b) continue;
    entries.emplace_back(a, b, w);
    entries.emplace_back(b, a, w);
  }
  std::sort(entries.begin(), entries.end());
  WeightedAdjacency out;
  out.offsets.assign(tri.num_vertices + 1, 0);
  for (std::size_t p = 0; p < entries.size(); ++p) {
    const auto [i, j, w] = entries[p];
    if (!out.neighbors.empty() && p > 0 && std::get<0>(entries[p - 1]) == i &&
        std::get<1>(entries[p - 1]) == j) {
      out.weights.back() += w;
      continue;
    }
    out.neighbors.push_back(j);
    out.weights.push_back(w);
    ++out.offsets[i + 1];
  }
  for (int i = 0; i < tri.num_vertices; ++i) out.offsets[i + 1] += out.offsets[i];
  return out;
}

// Rows failing kMinRowSumFraction replaced by uniform weights over the mesh's one-ring.
WeightedAdjacency GuardRows(const WeightedAdjacency& weights, const VertexAdjacency& adjacency,
                            LaplacianWeightReport* report) {
  const int n = static_cast<int>(adjacency.offsets.size()) - 1;
  WeightedAdjacency out;
  out.offsets.assign(1, 0);
  out.neighbors.reserve(weights.neighbors.size());
  out.weights.reserve(weights.weights.size());
  for (int i = 0; i < n; ++i) {
    double sum = 0, magnitude = 0;
    for (int p = weights.offsets[i]; p < weights.offsets[i + 1]; ++p) {
      sum += weights.weights[p];
      magnitude += std::abs(weights.weights[p]);
    }
    if (std::isfinite(sum) && magnitude > 0 && sum > kMinRowSumFraction * magnitude) {
      out.neighbors.insert(out.neighbors.end(), weights.neighbors.begin() + weights.offsets[i],
                           weights.neighbors.begin() + weights.offsets[i + 1]);
      out.weights.insert(out.weights.end(), weights.weights.begin() + weights.offsets[i],
                         weights.weights.begin() + weights.offsets[i + 1]);
    } else {
      ++report->uniform_rows;
      out.neighbors.insert(out.neighbors.end(), adjacency.neighbors.begin() + adjacency.offsets[i],
                           adjacency.neighbors.begin() + adjacency.offsets[i + 1]);
      out.weights.insert(out.weights.end(), adjacency.degree(i), 1.0);
    }
    out.offsets.push_back(static_cast<int>(out.neighbors.size()));
  }
  return out;
}

// Vertex pairs of `weights` that are not one-ring neighbours in `adjacency` (each pair once).
int NewNeighborPairs(const WeightedAdjacency& weights, const VertexAdjacency& adjacency) {
  int count = 0;
  const int n = static_cast<int>(adjacency.offsets.size()) - 1;
  for (int i = 0; i < n; ++i) {
    const auto begin = adjacency.neighbors.begin() + adjacency.offsets[i];
    const auto end = adjacency.neighbors.begin() + adjacency.offsets[i + 1];
    for (int p = weights.offsets[i]; p < weights.offsets[i + 1]; ++p) {
      const int j = weights.neighbors[p];
      if (j > i && !std::binary_search(begin, end, j)) ++count;
    }
  }
  return count;
}

}  // namespace

WeightedAdjacency BuildLaplacianWeights(const TriangleMesh& mesh, const VertexAdjacency& adjacency,
                                        LaplacianWeights kind, LaplacianWeightReport* report) {
  LaplacianWeightReport local;
  if (report == nullptr) report = &local;
  *report = {};
  report->kind = kind;
  if (kind == LaplacianWeights::kUniform) {
    report->edges = static_cast<int>(adjacency.neighbors.size()) / 2;
    return UniformWeights(adjacency);
  }
  IntrinsicTriangulation tri = TriangulationOfMesh(mesh);
  const bool intrinsic = kind == LaplacianWeights::kIntrinsicCotangent;
  if (intrinsic) report->flips = FlipToDelaunay(&tri);
  report->edges = tri.num_edges();
  WeightedAdjacency weights = GuardRows(EdgeWeights(tri, intrinsic, report), adjacency, report);
  if (intrinsic) report->new_neighbor_pairs = NewNeighborPairs(weights, adjacency);
  return weights;
}

}  // namespace deform
