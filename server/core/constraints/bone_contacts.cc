#include "core/constraints/bone_contacts.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <string>
#include <utility>

namespace deform {

StatusOr<std::shared_ptr<const BoneContacts>> BoneContacts::Create(
    std::vector<BoneSurface> surfaces, const Skeleton& skeleton, const TriangleMesh& skin,
    const std::vector<int>& rigid_bones, const MeshLimits& limits) {
  DEFORM_RETURN_IF_ERROR(ValidateBoneSurfaces(surfaces, skeleton, limits));
  std::shared_ptr<BoneContacts> contacts(new BoneContacts());
  contacts->skeleton_ = skeleton;
  for (BoneSurface& surface : surfaces) {
    Surface entry;
    entry.bvh = std::make_unique<TriangleBvh>(surface.mesh);
    entry.side = SurfaceSide::Make(*entry.bvh);
    for (int i = 0; i < skin.num_vertices(); ++i) {
      const bool carried = i < static_cast<int>(rigid_bones.size()) &&
                           rigid_bones[i] == surface.bone && surface.blend_bone < 0;
      if (!carried) entry.candidates.push_back(i);
    }
    // Principal axes: a long bone's box then hugs it whatever its direction.
    const Positions& v = surface.mesh.vertices;
    const Eigen::RowVector3d mean = v.colwise().mean();
    const Eigen::Matrix3d covariance = (v.rowwise() - mean).transpose() * (v.rowwise() - mean);
    entry.box_axes =
        Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(covariance).eigenvectors().transpose();
    const Positions in_box = v * entry.box_axes.transpose();
    entry.box_lower = in_box.colwise().minCoeff().transpose();
    entry.box_upper = in_box.colwise().maxCoeff().transpose();
    entry.surface = std::move(surface);
    contacts->surfaces_.push_back(std::move(entry));
  }
  // The rest skin must be outside every surface.
  const std::vector<RigidTransform> rest(skeleton.num_bones());
  for (int s = 0; s < contacts->num_surfaces(); ++s) {
    for (int i = 0; i < skin.num_vertices(); ++i) {
      BonePenetration inside;
      if (contacts->Penetration(s, RigidTransform{}, skin.vertices.row(i).transpose(), &inside)) {
        return Status::InvalidArgument(
            "skin vertex " + std::to_string(i) + " is inside bone surface '" +
            contacts->surface(s).name + "' at rest (by " + std::to_string(inside.depth) +
            " model units): are the bones in the skin's units and frame?");
      }
    }
  }
  return std::shared_ptr<const BoneContacts>(std::move(contacts));
}

std::vector<BoneSurface> BoneContacts::Surfaces() const {
  std::vector<BoneSurface> out;
  for (const Surface& s : surfaces_) out.push_back(s.surface);
  return out;
}

bool BoneContacts::Penetration(int s, const RigidTransform& pose, const Eigen::Vector3d& x,
                               BonePenetration* out) const {
  const Surface& surface = surfaces_[s];
  // In the surface's rest frame, where its tree was built.
  const Eigen::Vector3d local = pose.rotation.conjugate() * (x - pose.translation);
  const Eigen::Vector3d in_box = surface.box_axes * local;
  if ((in_box.array() < surface.box_lower.array()).any() ||
      (in_box.array() > surface.box_upper.array()).any()) {
    return false;
  }
  TriangleBvh::SurfacePoint nearest;
  if (surface.side != nullptr) {
    // One nearest-point query answers the side and the depth; rays only where it is unsure.
    nearest = surface.bvh->ClosestPoint(local);
    const SurfaceSide::Side side = surface.side->Of(local, nearest);
    if (side == SurfaceSide::Side::kOutside) return false;
    if (side == SurfaceSide::Side::kUnsure && !surface.bvh->Contains(local)) return false;
  } else {
    if (!surface.bvh->Contains(local)) return false;
    nearest = surface.bvh->ClosestPoint(local);
  }
  // Outward: from the inside point to its nearest surface point; on the surface, the face's.
  const double scale = (surface.bvh->upper() - surface.bvh->lower()).norm();
  const Eigen::Vector3d normal = nearest.distance > 1e-9 * scale
                                     ? Eigen::Vector3d((nearest.point - local) / nearest.distance)
                                     : surface.bvh->TriangleNormal(nearest.triangle);
  out->surface = s;
  out->depth = nearest.distance;
  out->normal = pose.rotation * normal;
  out->surface_point = pose.Apply(nearest.point);
  return true;
}

int BoneContacts::Find(const double* xyz, const std::vector<RigidTransform>& bones,
                       BonePenetration* out, int capacity, PenetrationSummary* summary,
                       const char* skip) const {
  *summary = {};
  int written = 0;
  // A min-heap on depth keeps the deepest `capacity` (no allocation: it lives in `out`).
  auto shallower = [](const BonePenetration& a, const BonePenetration& b) {
    return a.depth > b.depth;
  };
  for (int s = 0; s < num_surfaces(); ++s) {
    const RigidTransform pose = BoneSurfaceTransform(surfaces_[s].surface, skeleton_, bones);
    // The posed point in the surface's box frame, as one affine map (the cheap test first).
    const Eigen::Matrix3d to_box =
        surfaces_[s].box_axes * pose.rotation.conjugate().toRotationMatrix();
    const Eigen::Vector3d offset = to_box * pose.translation;
    const Eigen::Vector3d& lower = surfaces_[s].box_lower;
    const Eigen::Vector3d& upper = surfaces_[s].box_upper;
    for (int i : surfaces_[s].candidates) {
      const Eigen::Vector3d x(xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2]);
      const Eigen::Vector3d in_box = to_box * x - offset;
      if ((in_box.array() < lower.array()).any() || (in_box.array() > upper.array()).any()) {
        continue;
      }
      BonePenetration found;
      if (!Penetration(s, pose, x, &found)) continue;
      found.vertex = i;
      summary->max_depth = std::max(summary->max_depth, found.depth);
      // A vertex inside an earlier surface too is counted once and reported for the deeper.
      bool earlier = false;
      for (int e = 0; e < s && !earlier; ++e) {
        BonePenetration other;
        earlier = Penetration(e, BoneSurfaceTransform(surfaces_[e].surface, skeleton_, bones),
                              Eigen::Vector3d(xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2]), &other);
      }
      if (!earlier) ++summary->vertices;
      if (skip != nullptr && skip[i]) continue;
      if (earlier) {
        BonePenetration* same = std::find_if(
            out, out + written, [&](const BonePenetration& p) { return p.vertex == i; });
        if (same != out + written) {
          if (found.depth > same->depth) {
            *same = found;
            std::make_heap(out, out + written, shallower);
          }
          continue;
        }
      }
      if (written < capacity) {
        out[written++] = found;
        std::push_heap(out, out + written, shallower);
      } else if (capacity > 0 && found.depth > out[0].depth) {
        std::pop_heap(out, out + written, shallower);
        out[written - 1] = found;
        std::push_heap(out, out + written, shallower);
      }
    }
  }
  std::sort_heap(out, out + written, shallower);
  return written;
}

bool BoneContacts::Deepest(int vertex, const double* xyz, const std::vector<RigidTransform>& bones,
                           BonePenetration* out) const {
  bool inside = false;
  for (int s = 0; s < num_surfaces(); ++s) {
    BonePenetration found;
    if (Into(s, vertex, xyz, bones, &found) && (!inside || found.depth > out->depth)) {
      *out = found;
      inside = true;
    }
  }
  return inside;
}

bool BoneContacts::Into(int surface, int vertex, const double* xyz,
                        const std::vector<RigidTransform>& bones, BonePenetration* out) const {
  const Eigen::Vector3d x(xyz[3 * vertex], xyz[3 * vertex + 1], xyz[3 * vertex + 2]);
  if (!Penetration(surface, BoneSurfaceTransform(surfaces_[surface].surface, skeleton_, bones), x,
                   out)) {
    return false;
  }
  out->vertex = vertex;
  return true;
}

void BoneContacts::OutsidePlane(int surface, int vertex, const double* xyz,
                                const std::vector<RigidTransform>& bones,
                                BonePenetration* out) const {
  const Surface& entry = surfaces_[surface];
  const RigidTransform pose = BoneSurfaceTransform(entry.surface, skeleton_, bones);
  const Eigen::Vector3d x(xyz[3 * vertex], xyz[3 * vertex + 1], xyz[3 * vertex + 2]);
  const Eigen::Vector3d local = pose.rotation.conjugate() * (x - pose.translation);
  const TriangleBvh::SurfacePoint nearest = entry.bvh->ClosestPoint(local);
  // Outward: from the surface point to the outside point; on the surface, the face's.
  const double scale = (entry.bvh->upper() - entry.bvh->lower()).norm();
  const Eigen::Vector3d normal = nearest.distance > 1e-9 * scale
                                     ? Eigen::Vector3d((local - nearest.point) / nearest.distance)
                                     : entry.bvh->TriangleNormal(nearest.triangle);
  out->vertex = vertex;
  out->surface = surface;
  out->depth = -nearest.distance;
  out->normal = pose.rotation * normal;
  out->surface_point = pose.Apply(nearest.point);
}

PenetrationSummary BoneContacts::Measure(const Positions& posed,
                                         const std::vector<RigidTransform>& bones) const {
  PenetrationSummary summary;
  Find(posed.data(), bones, nullptr, 0, &summary);
  return summary;
}

}  // namespace deform
