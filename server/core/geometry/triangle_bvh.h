// A bounding-volume hierarchy over a triangle mesh's faces, for the queries binding needs: does a
// segment cross the surface, how many times does a ray cross it, is a point inside a closed mesh;
// and for the quality report's count of intersecting triangle pairs.
//
// Built once in O(F log F) (axis-aligned boxes, median split on the longest axis, at most
// kLeafTriangles per leaf); holds its own copy of the positions and triangles. Queries are const,
// allocate nothing beyond a small fixed stack, and are safe from any number of threads. Refit
// moves the vertices (same topology) and recomputes the boxes in O(F) without allocating, for a
// surface that deforms frame by frame; the tree's split stays the one built at rest.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <vector>

#include "core/geometry/mesh.h"

namespace deform {

class TriangleBvh {
 public:
  static constexpr int kLeafTriangles = 4;

  explicit TriangleBvh(const TriangleMesh& mesh);

  // Whether the segment from `from` to `to` crosses a triangle of the mesh, ignoring the triangles
  // that have `skip_vertex` as a corner (pass the vertex the segment starts at, or -1) and hits
  // closer than `margin` to either end (model units). Grazing an edge counts as a crossing.
  bool SegmentCrossesSurface(const Eigen::Vector3d& from, const Eigen::Vector3d& to,
                             int skip_vertex, double margin) const;

  // The number of triangles the ray origin + t direction, t > 0, crosses.
  int CountRayCrossings(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction) const;

  // Whether `point` lies inside the surface: the parity of the crossings of three rays in fixed,
  // skew directions, by majority. Meaningful for closed meshes; for an open mesh it answers for
  // the surface closed by whatever the rays see.
  bool Contains(const Eigen::Vector3d& point) const;

  // The smallest distance from `point` to the surface (exact, by descending the tree).
  double DistanceToSurface(const Eigen::Vector3d& point) const;

  // Where on its triangle a nearest point lies: inside the face, on an edge (between the
  // triangle's corners 0 and 1, 1 and 2, 2 and 0) or at a corner.
  enum class Feature : std::uint8_t {
    kFace,
    kEdge01,
    kEdge12,
    kEdge20,
    kCorner0,
    kCorner1,
    kCorner2
  };
  // The point of the surface nearest to `point`, the triangle it lies on, where on it, and its
  // distance (exact, by descending the tree). For an empty mesh: triangle -1, distance infinity.
  struct SurfacePoint {
    Eigen::Vector3d point = Eigen::Vector3d::Zero();
    int triangle = -1;
    double distance = 0;
    Feature feature = Feature::kFace;
  };
  SurfacePoint ClosestPoint(const Eigen::Vector3d& point) const;
  // The closest pair between the segment [from, to] (from == to: a point) and the surface: the
  // surface point, the triangle it lies on, the segment's point and their distance (exact, by
  // descending the tree; 0 when the segment crosses the surface). For an empty mesh: triangle
  // -1, distance infinity.
  struct SegmentSurfacePoint {
    Eigen::Vector3d point = Eigen::Vector3d::Zero();    // on the surface
    Eigen::Vector3d segment = Eigen::Vector3d::Zero();  // on the segment
    int triangle = -1;
    double distance = 0;
  };
  SegmentSurfacePoint ClosestPointToSegment(const Eigen::Vector3d& from,
                                            const Eigen::Vector3d& to) const;

  // Moves the vertices to `xyz` (row i at xyz[3 i], as many vertices as the tree was built with)
  // and refits every box to them, children before parents. O(F), no allocation. Not safe
  // while another thread queries this tree.
  void Refit(const double* xyz);
  int num_vertices() const { return static_cast<int>(positions_.rows()); }
  const Positions& positions() const { return positions_; }
  const Triangles& triangles() const { return triangles_; }
  // The unit normal of triangle f, by its winding (counter-clockwise seen from outside for an
  // outward-oriented mesh).
  Eigen::Vector3d TriangleNormal(int f) const;

  // The box of every triangle.
  const Eigen::Vector3d& lower() const { return nodes_.front().lower; }
  const Eigen::Vector3d& upper() const { return nodes_.front().upper; }
  // The number of unordered pairs of triangles that share no corner and pass through each other:
  // an edge of one crosses the inside of the other (a segment-triangle test on each of the six
  // edges), which for two triangles in general position is the same as their intersecting. Mere
  // contact (a corner on the other triangle, an edge grazing it, to 1e-9 of the barycentric
  // range) and coplanar overlaps are not counted. Triangles sharing a corner or an edge are never
  // counted: they touch by construction. Allocates nothing.
  int CountIntersectingTrianglePairs() const;

 private:
  struct Node {
    Eigen::Vector3d lower;
    Eigen::Vector3d upper;
    int first = 0;  // leaf: its triangles are order_[first, first + count)
    int count = 0;  // > 0 for a leaf, 0 for an inner node
    int left = -1;  // inner node: its children
    int right = -1;
  };

  int Build(int begin, int end);
  // Calls visit(triangle) for every triangle in a leaf whose box the segment [from, from + t dir],
  // t in [0, t_max], touches; stops early when visit returns true. Returns whether it stopped.
  template <typename Visit>
  bool ForEachCandidate(const Eigen::Vector3d& from, const Eigen::Vector3d& direction, double t_max,
                        Visit visit) const;
  // Calls visit(triangle) for every triangle in a leaf whose box overlaps [lower, upper].
  template <typename Visit>
  void ForEachInBox(const Eigen::Vector3d& lower, const Eigen::Vector3d& upper, Visit visit) const;
  // Whether triangles f and g (sharing no corner) intersect, as CountIntersectingTrianglePairs.
  bool TrianglesIntersect(int f, int g) const;
  // The parameter t > 0 at which the ray hits triangle f, or a negative number for no hit.
  double IntersectTriangle(int f, const Eigen::Vector3d& origin,
                           const Eigen::Vector3d& direction) const;

  Positions positions_;
  Triangles triangles_;
  std::vector<int> order_;  // triangle indices, grouped by leaf
  std::vector<Eigen::Vector3d> centroids_;
  std::vector<Node> nodes_;
};

}  // namespace deform
