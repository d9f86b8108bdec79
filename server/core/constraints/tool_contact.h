// The contact of one tool against the skin, for a haptic device that renders it every
// millisecond: the closest skin point to the tool's axis, the skin's outward normal there, how
// deep the tool is in, and the force of a stated spring model. The skin's triangles sit in a
// bounding-volume tree built once at rest and refitted (same topology) to each newer frame.
//
// Force model (docs/instruments.md): a spring on the depth along the skin's normal,
//   F = stiffness * w * (depth / L) * n,
// where `stiffness` is the force (in the client's force unit) of a press one bounding-box
// diagonal deep into material of weight 1, w the material weight at the closest point (the
// barycentric blend of its triangle's corners' weights), L the rest skin's bounding-box diagonal
// and n the outward normal. depth / L has no unit, so the force does not depend on the mesh's
// length unit and scales with the limb: the same relative press into a larger limb takes the
// same force.
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <memory>
#include <vector>

#include "core/base/status.h"
#include "core/constraints/tools.h"
#include "core/geometry/mesh.h"
#include "core/geometry/triangle_bvh.h"

namespace deform {

struct ContactForceModel {
  // The force of a press one diagonal deep into weight-1 material; > 0 and finite. Default: 100
  // (newtons when the client reads forces in newtons: a press of 1% of the diagonal gives 1).
  double stiffness = 100;
};

// INVALID_ARGUMENT "contact stiffness must be finite and > 0, got <value>" otherwise.
Status ValidateContactForceModel(const ContactForceModel& model);

struct SkinContact {
  Eigen::Vector3d point = Eigen::Vector3d::Zero();       // the skin point closest to the axis
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();      // the skin's outward unit normal there
  Eigen::Vector3d tool_point = Eigen::Vector3d::Zero();  // the axis point closest to the skin
  // The axis's distance from the skin, negative when the axis point is inside it (the sign of
  // (tool_point - point) along the angle-weighted pseudo-normal at `point`).
  double signed_distance = 0;
  // max(0, radius - signed_distance): > 0 when the tool is inside the skin, 0 when apart; a tool
  // whose surface just touches the skin has depth 0.
  double depth = 0;
  double material_weight = 0;                       // w at `point`
  Eigen::Vector3d force = Eigen::Vector3d::Zero();  // on the tool, by the force model
  int triangle = -1;                                // the triangle `point` lies on
};

class SkinContactQuery {
 public:
  // A query over `rest` (a valid mesh: ValidateMesh) with per-vertex material weights
  // `vertex_weights` (one per vertex, each finite and > 0; empty: all 1). INVALID_ARGUMENT for a
  // mesh without triangles or weights of the wrong count or value. O(F log F) for the tree.
  static StatusOr<std::unique_ptr<SkinContactQuery>> Create(const TriangleMesh& rest,
                                                            std::vector<double> vertex_weights);

  // Moves the skin to `xyz` (row i at xyz[3 i], num_vertices() rows, the frame's posed skin) and
  // refits the tree. O(F), no allocation. Not safe while another thread queries.
  void Refit(const double* xyz) { bvh_.Refit(xyz); }

  // The tool's contact with the skin as it stands (the rest pose or the last Refit). The tool
  // should be valid (ValidateTool). A sphere's axis is its centre; a capsule's the segment a-b.
  // A capsule whose axis crosses the skin reports distance 0 and depth = radius there. No
  // allocation; const, safe from several threads while nobody refits.
  SkinContact Query(const Tool& tool, const ContactForceModel& model) const;

  // The angle-weighted pseudo-normal at `point` on triangle `triangle` (Baerentzen and Aanaes):
  // the face's normal inside it, the sum of the two faces' normals on an edge, the angle-weighted
  // sum of the faces' normals at a corner; unit length. Its sign separates inside from outside
  // exactly for a closed, outward-oriented mesh.
  Eigen::Vector3d PseudoNormal(int triangle, const Eigen::Vector3d& point) const;

  // An upper bound on the bytes a query over a mesh of this size holds: the tree (positions,
  // triangles, order, at most one node per triangle), the vertices' faces and weights.
  static std::size_t BytesFor(int vertices, int triangles) {
    return static_cast<std::size_t>(vertices) *
               (3 * sizeof(double) + sizeof(double) + sizeof(int)) +
           static_cast<std::size_t>(triangles) *
               (3 * sizeof(int) + sizeof(int) + 3 * sizeof(int) + 64);
  }

  int num_vertices() const { return bvh_.num_vertices(); }
  double rest_diagonal() const { return rest_diagonal_; }
  const TriangleBvh& tree() const { return bvh_; }

 private:
  SkinContactQuery(const TriangleMesh& rest, std::vector<double> vertex_weights);
  // The unit normal of triangle f and its corner angle at vertex v (one of its corners).
  double CornerAngle(int f, int v) const;

  TriangleBvh bvh_;
  std::vector<int> vertex_face_offsets_;  // V + 1: vertex v's faces are vertex_faces_[o_v, o_v+1)
  std::vector<int> vertex_faces_;
  std::vector<double> weights_;  // per vertex
  double rest_diagonal_ = 0;
};

}  // namespace deform
