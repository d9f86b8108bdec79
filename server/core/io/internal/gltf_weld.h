// Internal to the glTF import: welding the vertices that glTF splits at UV or normal seams (and
// duplicates across primitives) back into one vertex each for the solve.
//
// Two file vertices are welded when their positions are exactly equal (the file's float values;
// -0 equals +0) and their normalized weights name the same bones with weights within
// kWeldWeightTolerance. Copies made for a seam are bit-identical in position, so no tolerance is
// needed there, and none risks joining vertices that are merely close. Coincident vertices with
// different weights stay apart (the mesh is then open there, as the file's own skinning is).
#pragma once

#include <vector>

#include "core/base/status.h"
#include "core/geometry/mesh.h"
#include "core/geometry/skin_weights.h"

namespace deform::gltf_internal {

inline constexpr double kWeldWeightTolerance = 1e-6;

struct WeldedMesh {
  TriangleMesh mesh;
  SkinWeights weights;
  // Per file vertex: its welded vertex. A vertex that no triangle uses is dropped from the mesh
  // and follows the used vertex before it in the file (the first used one, for those before it),
  // so every entry names a vertex of `mesh` (all -1 only when no triangle uses any vertex: the
  // mesh is then empty, which ValidateMesh refuses).
  std::vector<int> file_vertex_to_mesh;
  std::vector<int> unused_vertices;  // the file vertices no triangle uses, ascending
};

// `positions` and `weights` (normalized: entries sorted by bone) in file order; `triangles` index
// file vertices (in range). Welded vertices are numbered in order of first appearance in the file.
WeldedMesh WeldSeams(const Positions& positions, const SkinWeights& weights,
                     const Triangles& triangles);

}  // namespace deform::gltf_internal
