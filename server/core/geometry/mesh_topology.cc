#include "core/geometry/mesh_topology.h"

#include <algorithm>
#include <functional>
#include <limits>
#include <queue>
#include <utility>

namespace deform {

VertexAdjacency BuildVertexAdjacency(const Triangles& triangles, int num_vertices) {
  std::vector<std::vector<int>> lists(num_vertices);
  for (int f = 0; f < triangles.rows(); ++f) {
    for (int c = 0; c < 3; ++c) {
      const int a = triangles(f, c), b = triangles(f, (c + 1) % 3);
      lists[a].push_back(b);
      lists[b].push_back(a);
    }
  }
  VertexAdjacency adjacency;
  adjacency.offsets.assign(num_vertices + 1, 0);
  for (int i = 0; i < num_vertices; ++i) {
    std::sort(lists[i].begin(), lists[i].end());
    lists[i].erase(std::unique(lists[i].begin(), lists[i].end()), lists[i].end());
    adjacency.offsets[i + 1] = adjacency.offsets[i] + static_cast<int>(lists[i].size());
  }
  adjacency.neighbors.reserve(adjacency.offsets.back());
  for (const auto& list : lists) {
    adjacency.neighbors.insert(adjacency.neighbors.end(), list.begin(), list.end());
  }
  return adjacency;
}

int ConnectedComponents(const VertexAdjacency& adjacency, std::vector<int>* component) {
  const int n = static_cast<int>(adjacency.offsets.size()) - 1;
  component->assign(n, -1);
  std::vector<int> stack;
  int count = 0;
  for (int seed = 0; seed < n; ++seed) {
    if ((*component)[seed] >= 0) continue;
    (*component)[seed] = count;
    stack.push_back(seed);
    while (!stack.empty()) {
      const int v = stack.back();
      stack.pop_back();
      for (int p = adjacency.offsets[v]; p < adjacency.offsets[v + 1]; ++p) {
        const int u = adjacency.neighbors[p];
        if ((*component)[u] < 0) {
          (*component)[u] = count;
          stack.push_back(u);
        }
      }
    }
    ++count;
  }
  return count;
}

std::vector<double> SurfaceDistances(const Positions& vertices, const VertexAdjacency& adjacency,
                                     const std::vector<int>& sources,
                                     std::vector<int>* nearest_source) {
  const int n = static_cast<int>(vertices.rows());
  std::vector<double> distance(n, std::numeric_limits<double>::infinity());
  std::vector<int> source_of(n, -1);
  using Entry = std::pair<double, int>;
  std::priority_queue<Entry, std::vector<Entry>, std::greater<Entry>> queue;
  for (int s : sources) {
    distance[s] = 0;
    source_of[s] = s;
    queue.emplace(0.0, s);
  }
  while (!queue.empty()) {
    const auto [d, i] = queue.top();
    queue.pop();
    if (d > distance[i]) continue;
    for (int p = adjacency.offsets[i]; p < adjacency.offsets[i + 1]; ++p) {
      const int j = adjacency.neighbors[p];
      const double through = d + (vertices.row(i) - vertices.row(j)).norm();
      if (through < distance[j]) {
        distance[j] = through;
        source_of[j] = source_of[i];
        queue.emplace(through, j);
      }
    }
  }
  if (nearest_source != nullptr) *nearest_source = std::move(source_of);
  return distance;
}

bool IsClosed(const Triangles& triangles) {
  std::vector<std::pair<int, int>> edges;
  edges.reserve(3 * static_cast<std::size_t>(triangles.rows()));
  for (int f = 0; f < triangles.rows(); ++f) {
    for (int c = 0; c < 3; ++c) {
      const int a = triangles(f, c), b = triangles(f, (c + 1) % 3);
      edges.emplace_back(std::min(a, b), std::max(a, b));
    }
  }
  std::sort(edges.begin(), edges.end());
  for (std::size_t e = 0; e < edges.size();) {
    std::size_t same = e;
    while (same < edges.size() && edges[same] == edges[e]) ++same;
    if (same - e < 2) return false;
    e = same;
  }
  return true;
}

}  // namespace deform
