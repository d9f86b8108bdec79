#include "core/geometry/surface_side.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <unordered_map>

#include "core/geometry/mesh_topology.h"

namespace deform {
namespace {

std::int64_t DirectedEdge(int from, int to) {
  return (static_cast<std::int64_t>(from) << 32) | static_cast<std::uint32_t>(to);
}

using FaceOfEdge = std::unordered_map<std::int64_t, int>;  // directed edge -> its triangle

// The triangle running each directed edge, when every edge is run once in each direction: the
// surface is closed and consistently oriented (an edge of three or more triangles runs some
// direction twice). Empty otherwise.
FaceOfEdge FacesOfClosedOrientedEdges(const Triangles& triangles) {
  FaceOfEdge face_of;
  face_of.reserve(3 * static_cast<std::size_t>(triangles.rows()));
  for (int f = 0; f < triangles.rows(); ++f) {
    for (int e = 0; e < 3; ++e) {
      if (!face_of.emplace(DirectedEdge(triangles(f, e), triangles(f, (e + 1) % 3)), f).second)
        return {};
    }
  }
  for (const auto& [edge, face] : face_of) {
    const int from = static_cast<int>(edge >> 32);
    const int to = static_cast<int>(edge & 0xffffffff);
    if (face_of.find(DirectedEdge(to, from)) == face_of.end()) return {};
  }
  return face_of;
}

// Whether the triangles around every vertex form one fan. On a closed, oriented surface each
// triangle (v, a, b) around v links a to b; one fan is one cycle through all of them.
bool OneFanAtEveryCorner(const Triangles& triangles, int num_vertices) {
  std::vector<int> offsets(num_vertices + 1, 0);
  for (int f = 0; f < triangles.rows(); ++f) {
    for (int c = 0; c < 3; ++c) ++offsets[triangles(f, c) + 1];
  }
  for (int v = 0; v < num_vertices; ++v) offsets[v + 1] += offsets[v];
  std::vector<int> from(offsets.back()), to(offsets.back());
  std::vector<int> fill(offsets.begin(), offsets.end() - 1);
  for (int f = 0; f < triangles.rows(); ++f) {
    for (int c = 0; c < 3; ++c) {
      const int v = triangles(f, c);
      from[fill[v]] = triangles(f, (c + 1) % 3);
      to[fill[v]++] = triangles(f, (c + 2) % 3);
    }
  }
  for (int v = 0; v < num_vertices; ++v) {
    const int begin = offsets[v], count = offsets[v + 1] - begin;
    if (count == 0) continue;
    int at = from[begin];
    for (int step = 0; step < count; ++step) {
      int next = -1;
      for (int i = begin; i < begin + count && next < 0; ++i) {
        if (from[i] == at) next = to[i];
      }
      if (next < 0) return false;
      at = next;
      if (at == from[begin] && step + 1 < count) return false;  // a cycle short of the fan
    }
    if (at != from[begin]) return false;
  }
  return true;
}

// Whether every connected piece encloses a positive volume (outward normals).
bool EveryPieceOutward(const Positions& positions, const Triangles& triangles) {
  std::vector<int> piece;
  const int pieces = ConnectedComponents(
      BuildVertexAdjacency(triangles, static_cast<int>(positions.rows())), &piece);
  std::vector<double> volume(pieces, 0.0);
  std::vector<char> has_triangles(pieces, 0);  // a vertex no triangle uses is no piece
  for (int f = 0; f < triangles.rows(); ++f) {
    const Eigen::Vector3d a = positions.row(triangles(f, 0)).transpose();
    const Eigen::Vector3d b = positions.row(triangles(f, 1)).transpose();
    const Eigen::Vector3d c = positions.row(triangles(f, 2)).transpose();
    volume[piece[triangles(f, 0)]] += a.dot(b.cross(c)) / 6.0;
    has_triangles[piece[triangles(f, 0)]] = 1;
  }
  for (int p = 0; p < pieces; ++p) {
    if (has_triangles[p] && !(volume[p] > 0)) return false;
  }
  return true;
}

}  // namespace

std::unique_ptr<SurfaceSide> SurfaceSide::Make(const TriangleBvh& bvh) {
  const Positions& positions = bvh.positions();
  const Triangles& triangles = bvh.triangles();
  const int faces = static_cast<int>(triangles.rows());
  if (faces == 0) return nullptr;
  const double diagonal = (bvh.upper() - bvh.lower()).norm();
  std::unique_ptr<SurfaceSide> side(new SurfaceSide());
  side->on_surface_ = 1e-9 * diagonal;
  side->face_normals_.resize(faces);
  std::vector<Eigen::Vector3d> at_vertex(positions.rows(), Eigen::Vector3d::Zero());
  for (int f = 0; f < faces; ++f) {
    const Eigen::Vector3d p[3] = {positions.row(triangles(f, 0)).transpose(),
                                  positions.row(triangles(f, 1)).transpose(),
                                  positions.row(triangles(f, 2)).transpose()};
    const Eigen::Vector3d cross = (p[1] - p[0]).cross(p[2] - p[0]);
    if (!(cross.norm() > 1e-14 * diagonal * diagonal)) return nullptr;  // no area, or NaN
    side->face_normals_[f] = cross.normalized();
    for (int c = 0; c < 3; ++c) {
      const Eigen::Vector3d u = (p[(c + 1) % 3] - p[c]).normalized();
      const Eigen::Vector3d v = (p[(c + 2) % 3] - p[c]).normalized();
      const double angle = std::acos(std::clamp(u.dot(v), -1.0, 1.0));
      at_vertex[triangles(f, c)] += angle * side->face_normals_[f];
    }
  }
  const FaceOfEdge face_of = FacesOfClosedOrientedEdges(triangles);
  if (face_of.empty() || !OneFanAtEveryCorner(triangles, static_cast<int>(positions.rows())) ||
      !EveryPieceOutward(positions, triangles) || bvh.CountIntersectingTrianglePairs() != 0) {
    return nullptr;
  }
  side->corner_normals_.resize(3 * static_cast<std::size_t>(faces));
  for (int f = 0; f < faces; ++f) {
    for (int c = 0; c < 3; ++c) side->corner_normals_[3 * f + c] = at_vertex[triangles(f, c)];
  }
  // Each edge's pseudo-normal: the sum of its two triangles' normals, stored with both.
  side->edge_normals_.resize(3 * static_cast<std::size_t>(faces));
  for (int f = 0; f < faces; ++f) {
    for (int e = 0; e < 3; ++e) {
      const int other = face_of.at(DirectedEdge(triangles(f, (e + 1) % 3), triangles(f, e)));
      side->edge_normals_[3 * f + e] = side->face_normals_[f] + side->face_normals_[other];
    }
  }
  return side;
}

SurfaceSide::Side SurfaceSide::Of(const Eigen::Vector3d& point,
                                  const TriangleBvh::SurfacePoint& nearest) const {
  if (nearest.triangle < 0 || !(nearest.distance > on_surface_)) return Side::kUnsure;
  using Feature = TriangleBvh::Feature;
  const std::size_t f = static_cast<std::size_t>(nearest.triangle);
  const Eigen::Vector3d* normal = &face_normals_[f];
  switch (nearest.feature) {
    case Feature::kFace:
      break;
    case Feature::kEdge01:
    case Feature::kEdge12:
    case Feature::kEdge20:
      normal = &edge_normals_[3 * f + (static_cast<int>(nearest.feature) -
                                       static_cast<int>(Feature::kEdge01))];
      break;
    case Feature::kCorner0:
    case Feature::kCorner1:
    case Feature::kCorner2:
      normal = &corner_normals_[3 * f + (static_cast<int>(nearest.feature) -
                                         static_cast<int>(Feature::kCorner0))];
      break;
  }
  const double along = (point - nearest.point).dot(*normal);
  // Rounding cannot flip a sign this far from zero (relative to the vectors' lengths).
  if (!(std::abs(along) > 1e-7 * nearest.distance * normal->norm())) return Side::kUnsure;
  return along < 0 ? Side::kInside : Side::kOutside;
}

}  // namespace deform
