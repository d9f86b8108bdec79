#include "core/constraints/tool_contact.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <string>
#include <utility>

namespace deform {
namespace {

// Barycentric coordinates of `p` (on the triangle's plane) in triangle abc.
Eigen::Vector3d Barycentric(const Eigen::Vector3d& p, const Eigen::Vector3d& a,
                            const Eigen::Vector3d& b, const Eigen::Vector3d& c) {
  const Eigen::Vector3d v0 = b - a, v1 = c - a, v2 = p - a;
  const double d00 = v0.dot(v0), d01 = v0.dot(v1), d11 = v1.dot(v1);
  const double d20 = v2.dot(v0), d21 = v2.dot(v1);
  const double denominator = d00 * d11 - d01 * d01;
  if (!(denominator > 0)) return Eigen::Vector3d(1.0 / 3, 1.0 / 3, 1.0 / 3);
  const double v = (d11 * d20 - d01 * d21) / denominator;
  const double w = (d00 * d21 - d01 * d20) / denominator;
  return Eigen::Vector3d(1 - v - w, v, w);
}

// A barycentric coordinate at most this is on the triangle's border (an edge or a corner).
constexpr double kOnBorder = 1e-9;

}  // namespace

Status ValidateContactForceModel(const ContactForceModel& model) {
  if (!std::isfinite(model.stiffness) || !(model.stiffness > 0)) {
    return Status::InvalidArgument("contact stiffness must be finite and > 0, got " +
                                   std::to_string(model.stiffness));
  }
  return Status::Ok();
}

StatusOr<std::unique_ptr<SkinContactQuery>> SkinContactQuery::Create(
    const TriangleMesh& rest, std::vector<double> vertex_weights) {
  if (rest.num_triangles() == 0) {
    return Status::InvalidArgument("contact query: the skin has no triangles");
  }
  if (vertex_weights.empty()) vertex_weights.assign(rest.num_vertices(), 1.0);
  if (static_cast<int>(vertex_weights.size()) != rest.num_vertices()) {
    return Status::InvalidArgument("contact query: " + std::to_string(vertex_weights.size()) +
                                   " material weights for " + std::to_string(rest.num_vertices()) +
                                   " vertices");
  }
  for (std::size_t v = 0; v < vertex_weights.size(); ++v) {
    if (!std::isfinite(vertex_weights[v]) || !(vertex_weights[v] > 0)) {
      return Status::InvalidArgument("contact query: material weight of vertex " +
                                     std::to_string(v) + " must be finite and > 0, got " +
                                     std::to_string(vertex_weights[v]));
    }
  }
  return std::unique_ptr<SkinContactQuery>(new SkinContactQuery(rest, std::move(vertex_weights)));
}

SkinContactQuery::SkinContactQuery(const TriangleMesh& rest, std::vector<double> vertex_weights)
    : bvh_(rest),
      weights_(std::move(vertex_weights)),
      rest_diagonal_(BoundingBoxDiagonal(rest.vertices)) {
  const int vertices = rest.num_vertices();
  vertex_face_offsets_.assign(vertices + 1, 0);
  for (int f = 0; f < rest.num_triangles(); ++f) {
    for (int c = 0; c < 3; ++c) ++vertex_face_offsets_[rest.triangles(f, c) + 1];
  }
  for (int v = 0; v < vertices; ++v) vertex_face_offsets_[v + 1] += vertex_face_offsets_[v];
  vertex_faces_.resize(vertex_face_offsets_.back());
  std::vector<int> next(vertex_face_offsets_.begin(), vertex_face_offsets_.end() - 1);
  for (int f = 0; f < rest.num_triangles(); ++f) {
    for (int c = 0; c < 3; ++c) vertex_faces_[next[rest.triangles(f, c)]++] = f;
  }
}

double SkinContactQuery::CornerAngle(int f, int v) const {
  const Positions& x = bvh_.positions();
  const Triangles& t = bvh_.triangles();
  int corner = 0;
  while (corner < 2 && t(f, corner) != v) ++corner;
  const Eigen::Vector3d at = x.row(v).transpose();
  const Eigen::Vector3d e1 = x.row(t(f, (corner + 1) % 3)).transpose() - at;
  const Eigen::Vector3d e2 = x.row(t(f, (corner + 2) % 3)).transpose() - at;
  return std::atan2(e1.cross(e2).norm(), e1.dot(e2));
}

Eigen::Vector3d SkinContactQuery::PseudoNormal(int triangle, const Eigen::Vector3d& point) const {
  const Positions& x = bvh_.positions();
  const Triangles& t = bvh_.triangles();
  const Eigen::Vector3d bary =
      Barycentric(point, x.row(t(triangle, 0)).transpose(), x.row(t(triangle, 1)).transpose(),
                  x.row(t(triangle, 2)).transpose());
  int on_border = 0;
  for (int c = 0; c < 3; ++c) on_border += bary[c] <= kOnBorder ? 1 : 0;
  if (on_border == 0) return bvh_.TriangleNormal(triangle);
  if (on_border >= 2) {
    int corner = 0;
    bary.maxCoeff(&corner);
    const int v = t(triangle, corner);
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    for (int o = vertex_face_offsets_[v]; o < vertex_face_offsets_[v + 1]; ++o) {
      const int f = vertex_faces_[o];
      sum += CornerAngle(f, v) * bvh_.TriangleNormal(f);
    }
    return sum.norm() > 0 ? sum.normalized() : bvh_.TriangleNormal(triangle);
  }
  // On the edge opposite the corner whose coordinate vanishes: the faces holding both its ends.
  int opposite = 0;
  bary.minCoeff(&opposite);
  const int u = t(triangle, (opposite + 1) % 3);
  const int w = t(triangle, (opposite + 2) % 3);
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (int o = vertex_face_offsets_[u]; o < vertex_face_offsets_[u + 1]; ++o) {
    const int f = vertex_faces_[o];
    if (t(f, 0) == w || t(f, 1) == w || t(f, 2) == w) sum += bvh_.TriangleNormal(f);
  }
  return sum.norm() > 0 ? sum.normalized() : bvh_.TriangleNormal(triangle);
}

SkinContact SkinContactQuery::Query(const Tool& tool, const ContactForceModel& model) const {
  const Eigen::Vector3d& from = tool.a;
  const Eigen::Vector3d& to = tool.shape == Tool::Shape::kCapsule ? tool.b : tool.a;
  const TriangleBvh::SegmentSurfacePoint nearest = bvh_.ClosestPointToSegment(from, to);
  SkinContact contact;
  contact.triangle = nearest.triangle;
  contact.point = nearest.point;
  contact.tool_point = nearest.segment;
  contact.normal = PseudoNormal(nearest.triangle, nearest.point);
  const bool inside = (nearest.segment - nearest.point).dot(contact.normal) < 0;
  contact.signed_distance = inside ? -nearest.distance : nearest.distance;
  contact.depth = std::max(0.0, tool.radius - contact.signed_distance);
  const Triangles& t = bvh_.triangles();
  const Positions& x = bvh_.positions();
  const int f = nearest.triangle;
  const Eigen::Vector3d bary = Barycentric(nearest.point, x.row(t(f, 0)).transpose(),
                                           x.row(t(f, 1)).transpose(), x.row(t(f, 2)).transpose())
                                   .cwiseMax(0.0);
  const double total = bary.sum();
  contact.material_weight = 0;
  for (int c = 0; c < 3; ++c) contact.material_weight += bary[c] / total * weights_[t(f, c)];
  contact.force =
      model.stiffness * contact.material_weight * (contact.depth / rest_diagonal_) * contact.normal;
  return contact;
}

}  // namespace deform
