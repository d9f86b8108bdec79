#include "core/geometry/mesh.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cstddef>
#include <string>
#include <vector>

namespace deform {
namespace {

// A triangle is degenerate when its area is at most this fraction of the squared bounding-box
// diagonal. 1e-14 sits far below any real mesh (a 2M-vertex surface has triangles around
// 1e-7 d^2) yet well above the rounding noise of a double-precision cross product of exact
// collinear points.
constexpr double kDegenerateAreaTolerance = 1e-14;

Status CheckLimits(const TriangleMesh& mesh, const MeshLimits& limits) {
  if (static_cast<std::size_t>(mesh.vertices.rows()) > limits.max_vertices) {
    return Status::ResourceExhausted("mesh has " + std::to_string(mesh.vertices.rows()) +
                                     " vertices; the limit is " +
                                     std::to_string(limits.max_vertices));
  }
  if (static_cast<std::size_t>(mesh.triangles.rows()) > limits.max_triangles) {
    return Status::ResourceExhausted("mesh has " + std::to_string(mesh.triangles.rows()) +
                                     " triangles; the limit is " +
                                     std::to_string(limits.max_triangles));
  }
  return Status::Ok();
}

Status CheckNotEmpty(const TriangleMesh& mesh) {
  if (mesh.vertices.rows() == 0) return Status::InvalidArgument("mesh has no vertices");
  if (mesh.triangles.rows() == 0) return Status::InvalidArgument("mesh has no triangles");
  return Status::Ok();
}

Status CheckFiniteCoordinates(const Positions& vertices) {
  for (Eigen::Index v = 0; v < vertices.rows(); ++v) {
    if (!vertices.row(v).allFinite()) {
      return Status::InvalidArgument("vertex " + std::to_string(v) +
                                     " has a non-finite coordinate");
    }
  }
  return Status::Ok();
}

// Checks one triangle's indices (range, repetition) and its area against `min_area`.
Status CheckTriangle(const TriangleMesh& mesh, Eigen::Index t, double min_area) {
  const Eigen::Index num_vertices = mesh.vertices.rows();
  const auto corners = mesh.triangles.row(t);
  for (int c = 0; c < 3; ++c) {
    if (corners[c] < 0 || corners[c] >= num_vertices) {
      return Status::InvalidArgument("triangle " + std::to_string(t) + " references vertex " +
                                     std::to_string(corners[c]) + " but the mesh has " +
                                     std::to_string(num_vertices) + " vertices");
    }
  }
  for (int c = 0; c < 3; ++c) {
    if (corners[c] == corners[(c + 1) % 3]) {
      return Status::InvalidArgument("triangle " + std::to_string(t) +
                                     " is degenerate (it uses vertex " +
                                     std::to_string(corners[c]) + " twice)");
    }
  }
  const Eigen::Vector3d a = mesh.vertices.row(corners[0]).transpose();
  const Eigen::Vector3d b = mesh.vertices.row(corners[1]).transpose();
  const Eigen::Vector3d c = mesh.vertices.row(corners[2]).transpose();
  const double area = 0.5 * (b - a).cross(c - a).norm();
  if (area <= min_area) {
    return Status::InvalidArgument("triangle " + std::to_string(t) + " is degenerate (zero area)");
  }
  return Status::Ok();
}

Status CheckTriangles(const TriangleMesh& mesh) {
  const double diagonal = BoundingBoxDiagonal(mesh.vertices);
  const double min_area = kDegenerateAreaTolerance * diagonal * diagonal;
  for (Eigen::Index t = 0; t < mesh.triangles.rows(); ++t) {
    DEFORM_RETURN_IF_ERROR(CheckTriangle(mesh, t, min_area));
  }
  return Status::Ok();
}

// Precondition: every index is in range. Buckets each undirected edge under its smaller vertex
// (a counting sort, O(V + F)), then counts repeats within each vertex's short bucket.
Status CheckEdgeManifoldness(const TriangleMesh& mesh) {
  const std::size_t num_vertices = static_cast<std::size_t>(mesh.vertices.rows());
  std::vector<std::size_t> bucket_start(num_vertices + 1, 0);
  const auto for_each_edge = [&mesh](const auto& visit) {
    for (Eigen::Index t = 0; t < mesh.triangles.rows(); ++t) {
      for (int c = 0; c < 3; ++c) {
        const int a = mesh.triangles(t, c);
        const int b = mesh.triangles(t, (c + 1) % 3);
        visit(std::min(a, b), std::max(a, b));
      }
    }
  };
  for_each_edge([&](int low, int) { ++bucket_start[static_cast<std::size_t>(low) + 1]; });
  for (std::size_t v = 0; v < num_vertices; ++v) bucket_start[v + 1] += bucket_start[v];

  std::vector<int> high_ends(bucket_start.back());
  std::vector<std::size_t> fill = bucket_start;
  for_each_edge(
      [&](int low, int high) { high_ends[fill[static_cast<std::size_t>(low)]++] = high; });

  for (std::size_t v = 0; v < num_vertices; ++v) {
    const auto begin = high_ends.begin() + static_cast<std::ptrdiff_t>(bucket_start[v]);
    const auto end = high_ends.begin() + static_cast<std::ptrdiff_t>(bucket_start[v + 1]);
    std::sort(begin, end);
    for (auto run = begin; run != end;) {
      const auto run_end = std::upper_bound(run, end, *run);
      const auto sharing = run_end - run;
      if (sharing > 2) {
        return Status::InvalidArgument("edge (" + std::to_string(v) + "," + std::to_string(*run) +
                                       ") is shared by " + std::to_string(sharing) +
                                       " triangles (non-manifold)");
      }
      run = run_end;
    }
  }
  return Status::Ok();
}

// Precondition: every index is in range.
Status CheckAllVerticesUsed(const TriangleMesh& mesh) {
  std::vector<bool> used(static_cast<std::size_t>(mesh.vertices.rows()), false);
  for (Eigen::Index t = 0; t < mesh.triangles.rows(); ++t) {
    for (int c = 0; c < 3; ++c) used[static_cast<std::size_t>(mesh.triangles(t, c))] = true;
  }
  for (std::size_t v = 0; v < used.size(); ++v) {
    if (!used[v]) {
      return Status::InvalidArgument("vertex " + std::to_string(v) +
                                     " is not used by any triangle");
    }
  }
  return Status::Ok();
}

}  // namespace

// Checks run in this order, each over the whole mesh, and the first failure is returned: limits,
// emptiness, finite coordinates, per-triangle checks (indices, repeated vertex, area at most
// 1e-14 * diagonal^2), edges shared by more than two triangles, unused vertices. Open (boundary)
// meshes are valid. O(V + F) time and memory.
Status ValidateMesh(const TriangleMesh& mesh, const MeshLimits& limits) {
  DEFORM_RETURN_IF_ERROR(CheckLimits(mesh, limits));
  DEFORM_RETURN_IF_ERROR(CheckNotEmpty(mesh));
  DEFORM_RETURN_IF_ERROR(CheckFiniteCoordinates(mesh.vertices));
  DEFORM_RETURN_IF_ERROR(CheckTriangles(mesh));
  DEFORM_RETURN_IF_ERROR(CheckEdgeManifoldness(mesh));
  DEFORM_RETURN_IF_ERROR(CheckAllVerticesUsed(mesh));
  return Status::Ok();
}

double BoundingBoxDiagonal(const Positions& vertices) {
  if (vertices.rows() == 0) return 0.0;
  return (vertices.colwise().maxCoeff() - vertices.colwise().minCoeff()).norm();
}

}  // namespace deform
