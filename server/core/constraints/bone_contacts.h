// Where a posed skin enters its bone surfaces: the query a frame's contact constraints and every
// method's bone_penetration measure share.
#pragma once

#include <Eigen/Core>
#include <memory>
#include <vector>

#include "core/base/status.h"
#include "core/geometry/bone_surface.h"
#include "core/geometry/mesh.h"
#include "core/geometry/pose.h"
#include "core/geometry/skeleton.h"
#include "core/geometry/surface_side.h"
#include "core/geometry/triangle_bvh.h"

namespace deform {

// A skin vertex inside a bone surface.
struct BonePenetration {
  int vertex = -1;
  int surface = -1;
  double depth = 0;  // distance to the surface, > 0 (model units)
  // Outward unit normal and the nearest surface point, posed (world frame).
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();
  Eigen::Vector3d surface_point = Eigen::Vector3d::Zero();
};

struct PenetrationSummary {
  int vertices = 0;      // skin vertices inside some bone surface
  double max_depth = 0;  // the deepest, model units (0 when none)
};

class BoneContacts {
 public:
  // Checks the surfaces (ValidateBoneSurfaces) and refuses (INVALID_ARGUMENT, naming the vertex
  // and the surface) a rest skin that already enters one: bones placed in the wrong units or
  // frame would otherwise be "corrected" every frame. `rigid_bones` (per skin vertex, the bone
  // whose rigid zone it is in, or -1; may be empty) leaves out the vertices of a surface's own
  // bone's rigid zone, which move with it and so never enter it.
  static StatusOr<std::shared_ptr<const BoneContacts>> Create(std::vector<BoneSurface> surfaces,
                                                              const Skeleton& skeleton,
                                                              const TriangleMesh& skin,
                                                              const std::vector<int>& rigid_bones,
                                                              const MeshLimits& limits = {});

  int num_surfaces() const { return static_cast<int>(surfaces_.size()); }
  const BoneSurface& surface(int s) const { return surfaces_[s].surface; }
  std::vector<BoneSurface> Surfaces() const;

  // The posed skin's vertices inside a surface (`xyz`: row i at xyz[3 i]), with `bones` the
  // frame's bone transforms. Writes at most `capacity` of them, deepest first when there are
  // more, into `out` and returns how many it wrote; `summary` counts them all. A vertex inside
  // two surfaces is reported for the deeper. `skip` (per vertex, may be null): vertices not to
  // report (they still count in the summary). No allocation.
  int Find(const double* xyz, const std::vector<RigidTransform>& bones, BonePenetration* out,
           int capacity, PenetrationSummary* summary, const char* skip = nullptr) const;

  // Vertex `vertex`'s deepest penetration into any surface, or false when it is inside none.
  bool Deepest(int vertex, const double* xyz, const std::vector<RigidTransform>& bones,
               BonePenetration* out) const;

  // Vertex `vertex`'s penetration into surface `surface`, or false when it is outside it.
  bool Into(int surface, int vertex, const double* xyz, const std::vector<RigidTransform>& bones,
            BonePenetration* out) const;

  // For a vertex outside surface `surface` (Into false): the nearest surface point, the outward
  // normal there, and `depth` minus the distance. For a contact a frame carries over from the
  // last one (SkinConstraints).
  void OutsidePlane(int surface, int vertex, const double* xyz,
                    const std::vector<RigidTransform>& bones, BonePenetration* out) const;

  // Find's summary alone, for measuring any method's frame.
  PenetrationSummary Measure(const Positions& posed,
                             const std::vector<RigidTransform>& bones) const;

 private:
  struct Surface {
    BoneSurface surface;
    std::unique_ptr<TriangleBvh> bvh;
    // Its pseudo-normals when they answer for it (SurfaceSide::Make): the side of a point from
    // its nearest point alone; null: the tree's ray parity (TriangleBvh::Contains).
    std::unique_ptr<SurfaceSide> side;
    std::vector<int> candidates;  // skin vertices that may enter it
    // Its tight box: in the frame of its principal axes (rest frame to box frame), the bounds.
    Eigen::Matrix3d box_axes = Eigen::Matrix3d::Identity();
    Eigen::Vector3d box_lower = Eigen::Vector3d::Zero();
    Eigen::Vector3d box_upper = Eigen::Vector3d::Zero();
  };
  BoneContacts() = default;
  // The penetration of the posed point `x` into surface s posed by `pose`, or false.
  bool Penetration(int s, const RigidTransform& pose, const Eigen::Vector3d& x,
                   BonePenetration* out) const;

  Skeleton skeleton_;
  std::vector<Surface> surfaces_;
};

}  // namespace deform
