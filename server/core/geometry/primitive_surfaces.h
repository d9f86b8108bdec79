// Closed, outward-oriented triangle surfaces of simple solids: the bones the phantom and the tests
// place inside a skin, and the tools of a frame.
#pragma once

#include <Eigen/Core>

#include "core/geometry/mesh.h"

namespace deform {

// A capsule: the points within `radius` of the segment from `a` to `b` (a sphere when a == b).
// `segments` around the axis (at least 3), `cap_rings` rings per hemisphere (at least 1).
TriangleMesh MakeCapsule(const Eigen::Vector3d& a, const Eigen::Vector3d& b, double radius,
                         int segments = 16, int cap_rings = 4);

// An ellipsoid: center + axes * u for the unit sphere's points u (the columns of `axes` are its
// semi-axes; a right-handed frame keeps the surface outward). `segments` around, `rings` from
// pole to pole (at least 2).
TriangleMesh MakeEllipsoid(const Eigen::Vector3d& center, const Eigen::Matrix3d& axes,
                           int segments = 16, int rings = 8);

}  // namespace deform
