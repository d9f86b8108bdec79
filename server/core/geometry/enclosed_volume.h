// The volume a triangle mesh encloses.
#pragma once

#include "core/geometry/mesh.h"

namespace deform {

// Enclosed volume of the mesh with these positions. An open mesh is closed first by a fan from
// each boundary loop's centroid (computed from `positions`, so the cap moves with the mesh).
double EnclosedVolume(const Positions& positions, const Triangles& triangles);

}  // namespace deform
