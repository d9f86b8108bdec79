// The triangle surface mesh the core deforms, and its validation.
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <string>

#include "core/base/status.h"

namespace deform {

// Row-major so that a mesh's positions are one contiguous xyz,xyz,... buffer.
using Positions = Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>;  // #V by 3
using Triangles = Eigen::Matrix<int, Eigen::Dynamic, 3, Eigen::RowMajor>;     // #F by 3, 0-based

struct TriangleMesh {
  Positions vertices;
  Triangles triangles;

  int num_vertices() const { return static_cast<int>(vertices.rows()); }
  int num_triangles() const { return static_cast<int>(triangles.rows()); }
};

struct MeshLimits {
  // Meshes with more vertices are refused with RESOURCE_EXHAUSTED. Default: 2,000,000.
  std::size_t max_vertices = 2'000'000;
  // Meshes with more triangles are refused with RESOURCE_EXHAUSTED. Default: 4,000,000.
  std::size_t max_triangles = 4'000'000;
};

// Checks everything the deformation needs of a mesh and names the first problem found:
// no vertices or no triangles, NaN or infinite coordinates, indices out of range, a triangle that
// repeats a vertex or has zero area (relative to the bounding-box diagonal), an edge shared by more
// than two triangles (non-manifold), vertices no triangle uses, and sizes beyond `limits`.
// Returns INVALID_ARGUMENT (or RESOURCE_EXHAUSTED for limits) with a message that names the
// offending vertex or triangle index.
// Zero area means area <= 1e-14 * diagonal^2. Open (boundary) meshes are valid. O(V + F).
// The one definition of a usable mesh: the mesh readers (core/io/mesh_io.h) apply it to every mesh
// they return and DeformationModel::Build to its input; nothing else needs to.
Status ValidateMesh(const TriangleMesh& mesh, const MeshLimits& limits = {});

// Axis-aligned bounding-box diagonal length; 0 for an empty mesh.
double BoundingBoxDiagonal(const Positions& vertices);

}  // namespace deform
