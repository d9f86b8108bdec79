#include "core/geometry/triangle_bvh.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numeric>

namespace deform {
namespace {

constexpr int kMaxDepth = 64;  // a median split halves the triangles: depth <= log2(F) + 1

// A segment origin + t direction, t in [0, t_max], set up once for the slab tests of a descent:
// the reciprocal of each direction coordinate (infinite for a zero one).
struct SegmentSlabs {
  SegmentSlabs(const Eigen::Vector3d& origin_in, const Eigen::Vector3d& direction, double t_max_in)
      : origin(origin_in), t_max(t_max_in) {
    for (int axis = 0; axis < 3; ++axis) {
      parallel[axis] = std::abs(direction[axis]) < 1e-300;
      inverse[axis] = parallel[axis] ? 0.0 : 1.0 / direction[axis];
    }
  }
  Eigen::Vector3d origin;
  Eigen::Vector3d inverse;
  std::array<bool, 3> parallel{};
  double t_max;
};

// Whether the segment meets the box. The products by the reciprocal round differently from a
// division, so the interval is widened by a few units in the last place (Ize, "Robust BVH ray
// traversal", 2013): a box the segment grazes is never missed.
bool SegmentTouchesBox(const SegmentSlabs& segment, const Eigen::Vector3d& lower,
                       const Eigen::Vector3d& upper) {
  constexpr double kWiden = 4 * std::numeric_limits<double>::epsilon();
  double t0 = 0;
  double t1 = segment.t_max;
  for (int axis = 0; axis < 3; ++axis) {
    if (segment.parallel[axis]) {
      if (segment.origin[axis] < lower[axis] || segment.origin[axis] > upper[axis]) return false;
      continue;
    }
    double a = (lower[axis] - segment.origin[axis]) * segment.inverse[axis];
    double b = (upper[axis] - segment.origin[axis]) * segment.inverse[axis];
    if (a > b) std::swap(a, b);
    t0 = std::max(t0, a);
    t1 = std::min(t1, b + std::abs(b) * kWiden);
    if (t0 > t1) return false;
  }
  return true;
}

double SquaredDistanceToBox(const Eigen::Vector3d& p, const Eigen::Vector3d& lower,
                            const Eigen::Vector3d& upper) {
  const Eigen::Vector3d clamped = p.cwiseMax(lower).cwiseMin(upper);
  return (p - clamped).squaredNorm();
}

using Feature = TriangleBvh::Feature;

// Closest point of triangle abc to p (Ericson, Real-Time Collision Detection, 5.1.5), and the
// Voronoi region it was found in (`feature`, when given).
Eigen::Vector3d ClosestPointOnTriangle(const Eigen::Vector3d& p, const Eigen::Vector3d& a,
                                       const Eigen::Vector3d& b, const Eigen::Vector3d& c,
                                       Feature* feature = nullptr) {
  Feature ignored;
  Feature& region = feature != nullptr ? *feature : ignored;
  const Eigen::Vector3d ab = b - a, ac = c - a, ap = p - a;
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0 && d2 <= 0) {
    region = Feature::kCorner0;
    return a;
  }
  const Eigen::Vector3d bp = p - b;
  const double d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0 && d4 <= d3) {
    region = Feature::kCorner1;
    return b;
  }
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) {
    region = Feature::kEdge01;
    return a + d1 / (d1 - d3) * ab;
  }
  const Eigen::Vector3d cp = p - c;
  const double d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0 && d5 <= d6) {
    region = Feature::kCorner2;
    return c;
  }
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) {
    region = Feature::kEdge20;
    return a + d2 / (d2 - d6) * ac;
  }
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) {
    region = Feature::kEdge12;
    return b + (d4 - d3) / ((d4 - d3) + (d5 - d6)) * (c - b);
  }
  region = Feature::kFace;
  const double denominator = 1.0 / (va + vb + vc);
  return a + ab * (vb * denominator) + ac * (vc * denominator);
}

// Whether the segment [from, to] passes through the inside of triangle abc (Moller-Trumbore): the
// barycentrics and the segment parameter at least kProperCrossing inside their ranges, so that a
// corner resting on another triangle or an edge grazing it (contacts a generated mesh can have at
// rest) is not a crossing. A segment parallel to the plane does not cross it.
bool SegmentMeetsTriangle(const Eigen::Vector3d& from, const Eigen::Vector3d& to,
                          const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                          const Eigen::Vector3d& c) {
  constexpr double kProperCrossing = 1e-9;
  const Eigen::Vector3d direction = to - from;
  const Eigen::Vector3d e1 = b - a;
  const Eigen::Vector3d e2 = c - a;
  const Eigen::Vector3d p = direction.cross(e2);
  const double determinant = e1.dot(p);
  if (std::abs(determinant) < 1e-300) return false;
  const double inverse = 1.0 / determinant;
  const Eigen::Vector3d s = from - a;
  const double u = s.dot(p) * inverse;
  if (u < kProperCrossing || u > 1 - kProperCrossing) return false;
  const Eigen::Vector3d q = s.cross(e1);
  const double v = direction.dot(q) * inverse;
  if (v < kProperCrossing || u + v > 1 - kProperCrossing) return false;
  const double t = e2.dot(q) * inverse;
  return t > kProperCrossing && t < 1 - kProperCrossing;
}

// The closest points of segments [p1, q1] and [p2, q2] (Ericson, 5.1.9); returns the squared
// distance between them.
double ClosestPointsOfSegments(const Eigen::Vector3d& p1, const Eigen::Vector3d& q1,
                               const Eigen::Vector3d& p2, const Eigen::Vector3d& q2,
                               Eigen::Vector3d* c1, Eigen::Vector3d* c2) {
  constexpr double kDegenerate = 1e-300;
  const Eigen::Vector3d d1 = q1 - p1, d2 = q2 - p2, r = p1 - p2;
  const double a = d1.squaredNorm(), e = d2.squaredNorm(), f = d2.dot(r);
  double s = 0, t = 0;
  if (a <= kDegenerate && e <= kDegenerate) {
    s = t = 0;
  } else if (a <= kDegenerate) {
    t = std::clamp(f / e, 0.0, 1.0);
  } else {
    const double c = d1.dot(r);
    if (e <= kDegenerate) {
      s = std::clamp(-c / a, 0.0, 1.0);
    } else {
      const double b = d1.dot(d2);
      const double denominator = a * e - b * b;
      s = denominator > 0 ? std::clamp((b * f - c * e) / denominator, 0.0, 1.0) : 0.0;
      t = (b * s + f) / e;
      if (t < 0) {
        t = 0;
        s = std::clamp(-c / a, 0.0, 1.0);
      } else if (t > 1) {
        t = 1;
        s = std::clamp((b - c) / a, 0.0, 1.0);
      }
    }
  }
  *c1 = p1 + d1 * s;
  *c2 = p2 + d2 * t;
  return (*c1 - *c2).squaredNorm();
}

// The closest pair between segment [from, to] and triangle abc: the triangle's point, the
// segment's point; returns their squared distance. A segment through the triangle gives 0 at the
// crossing.
double ClosestSegmentTrianglePair(const Eigen::Vector3d& from, const Eigen::Vector3d& to,
                                  const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                                  const Eigen::Vector3d& c, Eigen::Vector3d* on_triangle,
                                  Eigen::Vector3d* on_segment) {
  const Eigen::Vector3d direction = to - from;
  if (direction.squaredNorm() > 0) {
    // A crossing (Moller-Trumbore, closed barycentric and segment ranges).
    const Eigen::Vector3d e1 = b - a, e2 = c - a;
    const Eigen::Vector3d p = direction.cross(e2);
    const double determinant = e1.dot(p);
    if (std::abs(determinant) > 1e-300) {
      const double inverse = 1.0 / determinant;
      const Eigen::Vector3d s = from - a;
      const double u = s.dot(p) * inverse;
      const Eigen::Vector3d q = s.cross(e1);
      const double v = direction.dot(q) * inverse;
      const double t = e2.dot(q) * inverse;
      if (u >= 0 && v >= 0 && u + v <= 1 && t >= 0 && t <= 1) {
        *on_segment = from + t * direction;
        *on_triangle = *on_segment;
        return 0;
      }
    }
  }
  // Otherwise the minimum lies at an end of the segment against the triangle or on an edge.
  *on_segment = from;
  *on_triangle = ClosestPointOnTriangle(from, a, b, c);
  double best = (*on_triangle - from).squaredNorm();
  if (direction.squaredNorm() == 0) return best;
  const Eigen::Vector3d at_to = ClosestPointOnTriangle(to, a, b, c);
  if ((at_to - to).squaredNorm() < best) {
    best = (at_to - to).squaredNorm();
    *on_segment = to;
    *on_triangle = at_to;
  }
  const std::array<std::pair<const Eigen::Vector3d*, const Eigen::Vector3d*>, 3> edges = {
      {{&a, &b}, {&b, &c}, {&c, &a}}};
  for (const auto& [start, end] : edges) {
    Eigen::Vector3d on_edge, on_axis;
    const double squared = ClosestPointsOfSegments(from, to, *start, *end, &on_axis, &on_edge);
    if (squared < best) {
      best = squared;
      *on_segment = on_axis;
      *on_triangle = on_edge;
    }
  }
  return best;
}

// A lower bound on the squared distance from segment [from, to] to the box: the larger of the
// distance between the segment's own box and the box, and the distance from its midpoint less
// its half length.
double SegmentBoxLowerBound(const Eigen::Vector3d& from, const Eigen::Vector3d& to,
                            const Eigen::Vector3d& lower, const Eigen::Vector3d& upper) {
  const Eigen::Vector3d segment_lower = from.cwiseMin(to);
  const Eigen::Vector3d segment_upper = from.cwiseMax(to);
  const Eigen::Vector3d gap = (lower - segment_upper).cwiseMax(segment_lower - upper).cwiseMax(0.0);
  const double boxes = gap.squaredNorm();
  const Eigen::Vector3d middle = 0.5 * (from + to);
  const double from_middle = std::max(
      0.0, std::sqrt(SquaredDistanceToBox(middle, lower, upper)) - 0.5 * (to - from).norm());
  return std::max(boxes, from_middle * from_middle);
}

bool BoxesOverlap(const Eigen::Vector3d& lower_a, const Eigen::Vector3d& upper_a,
                  const Eigen::Vector3d& lower_b, const Eigen::Vector3d& upper_b) {
  return (lower_a.array() <= upper_b.array()).all() && (lower_b.array() <= upper_a.array()).all();
}

}  // namespace

TriangleBvh::TriangleBvh(const TriangleMesh& mesh)
    : positions_(mesh.vertices), triangles_(mesh.triangles) {
  const int faces = static_cast<int>(triangles_.rows());
  order_.resize(faces);
  std::iota(order_.begin(), order_.end(), 0);
  centroids_.resize(faces);
  for (int f = 0; f < faces; ++f) {
    centroids_[f] = (positions_.row(triangles_(f, 0)) + positions_.row(triangles_(f, 1)) +
                     positions_.row(triangles_(f, 2)))
                        .transpose() /
                    3.0;
  }
  nodes_.reserve(2 * static_cast<std::size_t>(faces / kLeafTriangles + 1));
  if (faces > 0) Build(0, faces);
  std::vector<Eigen::Vector3d>().swap(centroids_);
}

// Builds the subtree over order_[begin, end); returns its node's index.
int TriangleBvh::Build(int begin, int end) {
  const int index = static_cast<int>(nodes_.size());
  nodes_.emplace_back();
  Eigen::Vector3d lower = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
  Eigen::Vector3d upper = -lower;
  for (int p = begin; p < end; ++p) {
    for (int c = 0; c < 3; ++c) {
      const Eigen::Vector3d v = positions_.row(triangles_(order_[p], c)).transpose();
      lower = lower.cwiseMin(v);
      upper = upper.cwiseMax(v);
    }
  }
  nodes_[index].lower = lower;
  nodes_[index].upper = upper;
  if (end - begin <= kLeafTriangles) {
    nodes_[index].first = begin;
    nodes_[index].count = end - begin;
    return index;
  }
  int axis = 0;
  (upper - lower).maxCoeff(&axis);
  const int middle = begin + (end - begin) / 2;
  std::nth_element(order_.begin() + begin, order_.begin() + middle, order_.begin() + end,
                   [&](int a, int b) { return centroids_[a][axis] < centroids_[b][axis]; });
  const int left = Build(begin, middle);
  const int right = Build(middle, end);
  nodes_[index].left = left;
  nodes_[index].right = right;
  return index;
}

template <typename Visit>
bool TriangleBvh::ForEachCandidate(const Eigen::Vector3d& from, const Eigen::Vector3d& direction,
                                   double t_max, Visit visit) const {
  if (triangles_.rows() == 0) return false;
  const SegmentSlabs segment(from, direction, t_max);
  std::array<int, kMaxDepth> stack;
  int top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const Node& node = nodes_[stack[--top]];
    if (!SegmentTouchesBox(segment, node.lower, node.upper)) continue;
    if (node.count > 0) {
      for (int p = node.first; p < node.first + node.count; ++p) {
        if (visit(order_[p])) return true;
      }
    } else {
      stack[top++] = node.left;
      stack[top++] = node.right;
    }
  }
  return false;
}

double TriangleBvh::IntersectTriangle(int f, const Eigen::Vector3d& origin,
                                      const Eigen::Vector3d& direction) const {
  // Moller-Trumbore; a hit on an edge or corner counts (a small tolerance on the barycentrics).
  constexpr double kEdgeTolerance = 1e-9;
  const Eigen::Vector3d a = positions_.row(triangles_(f, 0)).transpose();
  const Eigen::Vector3d e1 = positions_.row(triangles_(f, 1)).transpose() - a;
  const Eigen::Vector3d e2 = positions_.row(triangles_(f, 2)).transpose() - a;
  const Eigen::Vector3d p = direction.cross(e2);
  const double determinant = e1.dot(p);
  if (std::abs(determinant) < 1e-300) return -1;  // parallel to the triangle's plane
  const double inverse = 1.0 / determinant;
  const Eigen::Vector3d s = origin - a;
  const double u = s.dot(p) * inverse;
  if (u < -kEdgeTolerance || u > 1 + kEdgeTolerance) return -1;
  const Eigen::Vector3d q = s.cross(e1);
  const double v = direction.dot(q) * inverse;
  if (v < -kEdgeTolerance || u + v > 1 + kEdgeTolerance) return -1;
  return e2.dot(q) * inverse;
}

bool TriangleBvh::SegmentCrossesSurface(const Eigen::Vector3d& from, const Eigen::Vector3d& to,
                                        int skip_vertex, double margin) const {
  const Eigen::Vector3d direction = to - from;
  const double length = direction.norm();
  if (!(length > 2 * margin)) return false;
  const double t_low = margin / length;
  const double t_high = 1 - t_low;
  return ForEachCandidate(from, direction, 1.0, [&](int f) {
    if (triangles_(f, 0) == skip_vertex || triangles_(f, 1) == skip_vertex ||
        triangles_(f, 2) == skip_vertex) {
      return false;
    }
    const double t = IntersectTriangle(f, from, direction);
    return t >= t_low && t <= t_high;
  });
}

int TriangleBvh::CountRayCrossings(const Eigen::Vector3d& origin,
                                   const Eigen::Vector3d& direction) const {
  if (triangles_.rows() == 0) return 0;
  // The box test needs a finite end: beyond the root box nothing can be hit.
  const Node& root = nodes_[0];
  const double reach = (root.upper - root.lower).norm() + (origin - root.lower).norm() +
                       (origin - root.upper).norm();
  const double scale = reach / direction.norm();
  int crossings = 0;
  ForEachCandidate(origin, direction * scale, 1.0, [&](int f) {
    if (IntersectTriangle(f, origin, direction) > 0) ++crossings;
    return false;
  });
  return crossings;
}

bool TriangleBvh::Contains(const Eigen::Vector3d& point) const {
  if (triangles_.rows() == 0) return false;
  // Skew directions, unlikely to run along an edge of a modelled mesh.
  static const std::array<Eigen::Vector3d, 3> kDirections = {
      Eigen::Vector3d(0.5773, 0.5774, 0.5772), Eigen::Vector3d(-0.6123, 0.3536, -0.7071),
      Eigen::Vector3d(0.2672, -0.8018, 0.5345)};
  // By majority: when the first two agree the third cannot change the answer.
  const bool first = CountRayCrossings(point, kDirections[0]) % 2 == 1;
  const bool second = CountRayCrossings(point, kDirections[1]) % 2 == 1;
  if (first == second) return first;
  return CountRayCrossings(point, kDirections[2]) % 2 == 1;
}

TriangleBvh::SegmentSurfacePoint TriangleBvh::ClosestPointToSegment(
    const Eigen::Vector3d& from, const Eigen::Vector3d& to) const {
  SegmentSurfacePoint best;
  best.distance = std::numeric_limits<double>::infinity();
  if (triangles_.rows() == 0) return best;
  double best_squared = best.distance;
  std::array<int, kMaxDepth> stack;
  int top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const Node& node = nodes_[stack[--top]];
    if (SegmentBoxLowerBound(from, to, node.lower, node.upper) >= best_squared) continue;
    if (node.count > 0) {
      for (int p = node.first; p < node.first + node.count; ++p) {
        const int f = order_[p];
        Eigen::Vector3d on_triangle, on_segment;
        const double squared = ClosestSegmentTrianglePair(
            from, to, positions_.row(triangles_(f, 0)).transpose(),
            positions_.row(triangles_(f, 1)).transpose(),
            positions_.row(triangles_(f, 2)).transpose(), &on_triangle, &on_segment);
        if (squared < best_squared) {
          best_squared = squared;
          best = {on_triangle, on_segment, f, std::sqrt(squared)};
        }
      }
    } else {
      // Nearer child last, so it is popped first.
      const double left =
          SegmentBoxLowerBound(from, to, nodes_[node.left].lower, nodes_[node.left].upper);
      const double right =
          SegmentBoxLowerBound(from, to, nodes_[node.right].lower, nodes_[node.right].upper);
      stack[top++] = left < right ? node.right : node.left;
      stack[top++] = left < right ? node.left : node.right;
    }
  }
  return best;
}

void TriangleBvh::Refit(const double* xyz) {
  std::copy(xyz, xyz + positions_.size(), positions_.data());
  // Build pushes a node before its children, so every child's index exceeds its parent's.
  for (int n = static_cast<int>(nodes_.size()) - 1; n >= 0; --n) {
    Node& node = nodes_[n];
    if (node.count > 0) {
      node.lower = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
      node.upper = -node.lower;
      for (int p = node.first; p < node.first + node.count; ++p) {
        for (int c = 0; c < 3; ++c) {
          const Eigen::Vector3d v = positions_.row(triangles_(order_[p], c)).transpose();
          node.lower = node.lower.cwiseMin(v);
          node.upper = node.upper.cwiseMax(v);
        }
      }
    } else {
      node.lower = nodes_[node.left].lower.cwiseMin(nodes_[node.right].lower);
      node.upper = nodes_[node.left].upper.cwiseMax(nodes_[node.right].upper);
    }
  }
}

double TriangleBvh::DistanceToSurface(const Eigen::Vector3d& point) const {
  return ClosestPoint(point).distance;
}

TriangleBvh::SurfacePoint TriangleBvh::ClosestPoint(const Eigen::Vector3d& point) const {
  SurfacePoint best;
  best.distance = std::numeric_limits<double>::infinity();
  if (triangles_.rows() == 0) return best;
  std::array<int, kMaxDepth> stack;
  int top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const Node& node = nodes_[stack[--top]];
    if (SquaredDistanceToBox(point, node.lower, node.upper) >= best.distance * best.distance) {
      continue;
    }
    if (node.count > 0) {
      for (int p = node.first; p < node.first + node.count; ++p) {
        const int f = order_[p];
        Feature feature;
        const Eigen::Vector3d closest =
            ClosestPointOnTriangle(point, positions_.row(triangles_(f, 0)).transpose(),
                                   positions_.row(triangles_(f, 1)).transpose(),
                                   positions_.row(triangles_(f, 2)).transpose(), &feature);
        const double distance = (closest - point).norm();
        if (distance < best.distance) best = {closest, f, distance, feature};
      }
    } else {
      // Nearer child last, so it is popped first.
      const double left =
          SquaredDistanceToBox(point, nodes_[node.left].lower, nodes_[node.left].upper);
      const double right =
          SquaredDistanceToBox(point, nodes_[node.right].lower, nodes_[node.right].upper);
      stack[top++] = left < right ? node.right : node.left;
      stack[top++] = left < right ? node.left : node.right;
    }
  }
  return best;
}

Eigen::Vector3d TriangleBvh::TriangleNormal(int f) const {
  const Eigen::Vector3d a = positions_.row(triangles_(f, 0)).transpose();
  const Eigen::Vector3d b = positions_.row(triangles_(f, 1)).transpose();
  const Eigen::Vector3d c = positions_.row(triangles_(f, 2)).transpose();
  return (b - a).cross(c - a).normalized();
}

template <typename Visit>
void TriangleBvh::ForEachInBox(const Eigen::Vector3d& lower, const Eigen::Vector3d& upper,
                               Visit visit) const {
  if (triangles_.rows() == 0) return;
  std::array<int, kMaxDepth> stack;
  int top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const Node& node = nodes_[stack[--top]];
    if (!BoxesOverlap(lower, upper, node.lower, node.upper)) continue;
    if (node.count > 0) {
      for (int p = node.first; p < node.first + node.count; ++p) visit(order_[p]);
    } else {
      stack[top++] = node.left;
      stack[top++] = node.right;
    }
  }
}

bool TriangleBvh::TrianglesIntersect(int f, int g) const {
  std::array<Eigen::Vector3d, 3> first, second;
  for (int c = 0; c < 3; ++c) {
    first[c] = positions_.row(triangles_(f, c)).transpose();
    second[c] = positions_.row(triangles_(g, c)).transpose();
  }
  for (int e = 0; e < 3; ++e) {
    if (SegmentMeetsTriangle(first[e], first[(e + 1) % 3], second[0], second[1], second[2]) ||
        SegmentMeetsTriangle(second[e], second[(e + 1) % 3], first[0], first[1], first[2])) {
      return true;
    }
  }
  return false;
}

int TriangleBvh::CountIntersectingTrianglePairs() const {
  int pairs = 0;
  for (int f = 0; f < triangles_.rows(); ++f) {
    Eigen::Vector3d lower = positions_.row(triangles_(f, 0)).transpose();
    Eigen::Vector3d upper = lower;
    for (int c = 1; c < 3; ++c) {
      lower = lower.cwiseMin(positions_.row(triangles_(f, c)).transpose());
      upper = upper.cwiseMax(positions_.row(triangles_(f, c)).transpose());
    }
    ForEachInBox(lower, upper, [&](int g) {
      if (g <= f) return;  // each unordered pair once
      for (int a = 0; a < 3; ++a) {
        for (int b = 0; b < 3; ++b) {
          if (triangles_(f, a) == triangles_(g, b)) return;  // adjacent: they share a corner
        }
      }
      if (TrianglesIntersect(f, g)) ++pairs;
    });
  }
  return pairs;
}

}  // namespace deform
