#include "core/model/intrinsic_delaunay.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <utility>

namespace deform {
namespace {

// A side of a triangle: the corner that starts it, keyed by its two vertices in ascending order.
struct Side {
  std::int64_t key;
  int corner;
  bool operator<(const Side& other) const {
    return key != other.key ? key < other.key : corner < other.corner;
  }
};

std::int64_t EdgeKey(int a, int b) {
  return (static_cast<std::int64_t>(std::min(a, b)) << 32) |
         static_cast<std::uint32_t>(std::max(a, b));
}

// The sides of `corner_vertex`'s triangles sorted so that the two sides of an edge are adjacent.
std::vector<Side> SortedSides(const std::vector<int>& corner_vertex) {
  std::vector<Side> sides(corner_vertex.size());
  for (int h = 0; h < static_cast<int>(corner_vertex.size()); ++h) {
    sides[h] = {EdgeKey(corner_vertex[h], corner_vertex[IntrinsicTriangulation::Next(h)]), h};
  }
  std::sort(sides.begin(), sides.end());
  return sides;
}

// Per triangle, whether to reverse it so that the two sides of every edge run opposite ways (a
// breadth-first walk over each component; where a non-orientable component closes on itself the
// edge keeps two sides running the same way).
std::vector<char> Orientation(const std::vector<int>& corner_vertex,
                              const std::vector<Side>& sides) {
  const int triangles = static_cast<int>(corner_vertex.size()) / 3;
  std::vector<int> other_side(corner_vertex.size(), -1);
  for (std::size_t s = 0; s + 1 < sides.size(); ++s) {
    if (sides[s].key == sides[s + 1].key) {
      other_side[sides[s].corner] = sides[s + 1].corner;
      other_side[sides[s + 1].corner] = sides[s].corner;
    }
  }
  std::vector<char> reverse(triangles, 0), seen(triangles, 0);
  std::vector<int> queue;
  for (int start = 0; start < triangles; ++start) {
    if (seen[start]) continue;
    seen[start] = 1;
    queue.assign(1, start);
    for (std::size_t q = 0; q < queue.size(); ++q) {
      const int t = queue[q];
      for (int h = 3 * t; h < 3 * t + 3; ++h) {
        const int g = other_side[h];
        if (g < 0 || seen[g / 3]) continue;
        // The same direction as given (both start at the same vertex) needs one of them reversed.
        const bool same = corner_vertex[h] == corner_vertex[g];
        reverse[g / 3] = static_cast<char>(same != static_cast<bool>(reverse[t]));
        seen[g / 3] = 1;
        queue.push_back(g / 3);
      }
    }
  }
  return reverse;
}

// The length of the diagonal c-d of the quadrilateral of triangles (a, b, c) and (b, a, d) laid out
// in the plane on either side of a-b.
double FlippedLength(double ab, double bc, double ca, double ad, double db) {
  const double xc = (ab * ab + ca * ca - bc * bc) / (2 * ab);
  const double yc = std::sqrt(std::max(0.0, ca * ca - xc * xc));
  const double xd = (ab * ab + ad * ad - db * db) / (2 * ab);
  const double yd = std::sqrt(std::max(0.0, ad * ad - xd * xd));
  return std::hypot(xc - xd, yc + yd);
}

// Whether the three lengths make a triangle of positive area, by a relative margin.
bool IsTriangle(double a, double b, double c) {
  constexpr double kMargin = 1e-12;
  const double largest = std::max({a, b, c});
  return a + b + c - 2 * largest > kMargin * largest;
}

}  // namespace

double CornerCotangent(double opposite, double side_b, double side_c, bool* clamped) {
  double x = opposite, y = side_b, z = side_c;
  if (x < y) std::swap(x, y);
  if (x < z) std::swap(x, z);
  if (y < z) std::swap(y, z);
  const double product = (x + (y + z)) * (z - (x - y)) * (z + (x - y)) * (x + (y - z));
  const double four_area = product > 0 ? std::sqrt(product) : 0.0;
  const double numerator = side_b * side_b + side_c * side_c - opposite * opposite;
  if (std::abs(numerator) >= kMaxCotangent * four_area) {
    *clamped = true;
    return numerator < 0 ? -kMaxCotangent : (numerator > 0 ? kMaxCotangent : 0.0);
  }
  return numerator / four_area;
}

double IntrinsicTriangulation::OppositeCotangent(int h, bool* clamped) const {
  const int g = Next(h);
  return CornerCotangent(edge_length[corner_edge[h]], edge_length[corner_edge[g]],
                         edge_length[corner_edge[Next(g)]], clamped);
}

double IntrinsicTriangulation::CotangentWeight(int e, int* clamped) const {
  double sum = 0;
  for (int s = 0; s < 2; ++s) {
    const int h = edge_corners[2 * e + s];
    if (h < 0) continue;
    bool was_clamped = false;
    sum += OppositeCotangent(h, &was_clamped);
    if (clamped != nullptr && was_clamped) ++*clamped;
  }
  return sum / 2;
}

IntrinsicTriangulation TriangulationOfMesh(const TriangleMesh& mesh) {
  IntrinsicTriangulation tri;
  tri.num_vertices = mesh.num_vertices();
  const int triangles = mesh.num_triangles();
  tri.corner_vertex.resize(3 * static_cast<std::size_t>(triangles));
  for (int t = 0; t < triangles; ++t) {
    for (int k = 0; k < 3; ++k) tri.corner_vertex[3 * t + k] = mesh.triangles(t, k);
  }
  const std::vector<char> reverse = Orientation(tri.corner_vertex, SortedSides(tri.corner_vertex));
  for (int t = 0; t < triangles; ++t) {
    if (reverse[t]) std::swap(tri.corner_vertex[3 * t + 1], tri.corner_vertex[3 * t + 2]);
  }
  const std::vector<Side> sides = SortedSides(tri.corner_vertex);
  tri.corner_edge.resize(tri.corner_vertex.size());
  for (std::size_t s = 0; s < sides.size();) {
    const int e = tri.num_edges();
    const int h = sides[s].corner;
    tri.corner_edge[h] = e;
    tri.edge_corners.push_back(h);
    const bool paired = s + 1 < sides.size() && sides[s + 1].key == sides[s].key;
    const int g = paired ? sides[s + 1].corner : -1;
    if (paired) tri.corner_edge[g] = e;
    tri.edge_corners.push_back(g);
    tri.edge_flippable.push_back(static_cast<char>(
        paired && tri.corner_vertex[h] == tri.corner_vertex[IntrinsicTriangulation::Next(g)]));
    const int a = tri.corner_vertex[h], b = tri.corner_vertex[IntrinsicTriangulation::Next(h)];
    tri.edge_length.push_back((mesh.vertices.row(a) - mesh.vertices.row(b)).norm());
    s += paired ? 2 : 1;
  }
  return tri;
}

int FlipToDelaunay(IntrinsicTriangulation* tri, int max_flips) {
  using T = IntrinsicTriangulation;
  const int edges = tri->num_edges();
  if (max_flips < 0) max_flips = 100 * std::max(edges, 1);
  std::vector<int> queue(edges);
  std::vector<char> queued(edges, 1);
  for (int e = 0; e < edges; ++e) queue[e] = edges - 1 - e;
  int flips = 0;
  while (!queue.empty() && flips < max_flips) {
    const int e = queue.back();
    queue.pop_back();
    queued[e] = 0;
    if (!tri->edge_flippable[e] || tri->CotangentWeight(e) >= -kDelaunayTolerance) continue;
    // Edge e runs a -> b in triangle t0 = (a, b, c) and b -> a in t1 = (b, a, d).
    const int h0 = tri->edge_corners[2 * e], h1 = tri->edge_corners[2 * e + 1];
    const int t0 = h0 / 3, t1 = h1 / 3;
    if (t0 == t1) continue;
    const int h0n = T::Next(h0), h0p = T::Next(h0n), h1n = T::Next(h1), h1p = T::Next(h1n);
    const int a = tri->corner_vertex[h0], b = tri->corner_vertex[h0n];
    const int c = tri->corner_vertex[h0p], d = tri->corner_vertex[h1p];
    const int bc = tri->corner_edge[h0n], ca = tri->corner_edge[h0p];
    const int ad = tri->corner_edge[h1n], db = tri->corner_edge[h1p];
    const auto& len = tri->edge_length;
    const double cd = FlippedLength(len[e], len[bc], len[ca], len[ad], len[db]);
    if (!IsTriangle(cd, len[ca], len[ad]) || !IsTriangle(cd, len[db], len[bc])) continue;
    // The outer sides' slots in edge_corners, found before any is rewritten (two of the four may
    // be sides of one edge).
    const int outer_edges[4] = {ca, ad, db, bc};
    const int old_corners[4] = {h0p, h1n, h1p, h0n};
    const int new_corners[4] = {3 * t0 + 1, 3 * t0 + 2, 3 * t1 + 1, 3 * t1 + 2};
    int slots[4];
    for (int k = 0; k < 4; ++k) {
      const int o = outer_edges[k];
      slots[k] = tri->edge_corners[2 * o] == old_corners[k] ? 2 * o : 2 * o + 1;
    }
    // t0 becomes (d, c, a) and t1 (c, d, b): the new edge d -> c and c -> d, each outer side
    // keeping its direction.
    const int t0_vertices[3] = {d, c, a}, t0_edges[3] = {e, ca, ad};
    const int t1_vertices[3] = {c, d, b}, t1_edges[3] = {e, db, bc};
    for (int k = 0; k < 3; ++k) {
      tri->corner_vertex[3 * t0 + k] = t0_vertices[k];
      tri->corner_edge[3 * t0 + k] = t0_edges[k];
      tri->corner_vertex[3 * t1 + k] = t1_vertices[k];
      tri->corner_edge[3 * t1 + k] = t1_edges[k];
    }
    for (int k = 0; k < 4; ++k) tri->edge_corners[slots[k]] = new_corners[k];
    tri->edge_corners[2 * e] = 3 * t0;
    tri->edge_corners[2 * e + 1] = 3 * t1;
    tri->edge_length[e] = cd;
    ++flips;
    for (const int o : outer_edges) {
      if (!queued[o]) {
        queued[o] = 1;
        queue.push_back(o);
      }
    }
  }
  return flips;
}

}  // namespace deform
