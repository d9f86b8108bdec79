// Which side of a closed surface a point lies on, from the surface point nearest to it: the sign
// of (point - nearest) against the angle-weighted pseudo-normal of the face, edge or corner the
// nearest point lies on (Baerentzen and Aanaes, "Signed distance computation using the angle
// weighted pseudonormal", IEEE TVCG 2005). One nearest-point query answers both the side and the
// depth, where a parity test casts rays on top of it.
//
// The answer is exact only for a surface it holds for, so Make checks the surface first and
// returns null for any other (the caller then casts rays): every triangle of positive area; every
// edge shared by exactly two triangles that run it in opposite directions (closed, consistently
// oriented); the triangles around every corner one fan (no two cones touching at a vertex); no two
// triangles passing through each other (TriangleBvh::CountIntersectingTrianglePairs); and every
// connected piece enclosing a positive volume (outward normals; a cavity's inward piece is left to
// the rays). Real segmented bones may fail these: the rays stay their fallback.
//
// Immutable after Make; Side is const, allocation-free and safe from any number of threads.
#pragma once

#include <Eigen/Core>
#include <memory>
#include <vector>

#include "core/geometry/triangle_bvh.h"

namespace deform {

class SurfaceSide {
 public:
  // The pseudo-normals of the surface `bvh` was built over, or null when the surface is not one
  // they answer for (above).
  static std::unique_ptr<SurfaceSide> Make(const TriangleBvh& bvh);

  enum class Side { kInside, kOutside, kUnsure };
  // The side of `point`, whose nearest surface point is `nearest` (TriangleBvh::ClosestPoint, on
  // the same surface): kUnsure when the point is on the surface or so near the plane of its
  // nearest feature's normal that rounding could flip the sign (the caller casts rays then).
  Side Of(const Eigen::Vector3d& point, const TriangleBvh::SurfacePoint& nearest) const;

 private:
  SurfaceSide() = default;
  std::vector<Eigen::Vector3d> face_normals_;    // unit, per triangle
  std::vector<Eigen::Vector3d> edge_normals_;    // per triangle and edge (01, 12, 20): the sum of
                                                 // the two triangles' unit normals
  std::vector<Eigen::Vector3d> corner_normals_;  // per triangle and corner: its vertex's
                                                 // angle-weighted sum of normals
  double on_surface_ = 0;                        // a nearest distance below this is on the surface
};

}  // namespace deform
