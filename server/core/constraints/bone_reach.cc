#include "core/constraints/bone_reach.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <memory>
#include <utility>
#include <vector>

#include "core/geometry/pose.h"
#include "core/geometry/skeleton_geometry.h"
#include "core/geometry/triangle_bvh.h"

namespace deform {
namespace {

constexpr double kRadiansPerDegree = M_PI / 180;

// A surface's search tree and the ball around its rest vertices.
struct Reachable {
  std::unique_ptr<TriangleBvh> bvh;
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  double radius = 0;
};

// The turns a joint with degrees of freedom samples: each over its range, the others at rest.
std::vector<Eigen::Quaterniond> DegreeOfFreedomTurns(const Skeleton& skeleton, int joint,
                                                     const BoneReachOptions& options) {
  std::vector<Eigen::Quaterniond> turns;
  const double step = std::max(options.step_degrees, 0.5);
  const auto add = [&](double degrees, const Eigen::Vector3d& axis) {
    if (std::abs(degrees) > 1e-9) {
      turns.emplace_back(Eigen::AngleAxisd(degrees * kRadiansPerDegree, axis.normalized()));
    }
  };
  for (const DegreeOfFreedom& dof : skeleton.joint(joint).dofs) {
    const double low = std::max(dof.min_degrees, -180.0);
    const double high = std::min(dof.max_degrees, 180.0);
    for (double degrees = low; degrees < high; degrees += step) add(degrees, dof.axis);
    add(high, dof.axis);
  }
  return turns;
}

// Points filling surface s's solid (its vertices and a grid's points inside it), each as its
// distance from `pivot` and unit direction, sorted by distance; `spacing` the grid's step.
struct SolidSamples {
  std::vector<double> distance;
  std::vector<Eigen::Vector3d> direction;
  double spacing = 0;
};

SolidSamples SampleSolid(const BoneSurface& surface, const TriangleBvh& bvh,
                         const Eigen::Vector3d& pivot) {
  constexpr int kSteps = 24;  // along the box's longest side
  const Eigen::Vector3d lower = bvh.lower(), upper = bvh.upper();
  const double spacing = std::max((upper - lower).maxCoeff() / kSteps, 1e-12);
  std::vector<Eigen::Vector3d> points;
  for (Eigen::Index v = 0; v < surface.mesh.vertices.rows(); ++v) {
    points.push_back(surface.mesh.vertices.row(v).transpose());
  }
  for (double x = lower.x() + spacing / 2; x < upper.x(); x += spacing) {
    for (double y = lower.y() + spacing / 2; y < upper.y(); y += spacing) {
      for (double z = lower.z() + spacing / 2; z < upper.z(); z += spacing) {
        const Eigen::Vector3d p(x, y, z);
        if (bvh.Contains(p)) points.push_back(p);
      }
    }
  }
  std::vector<std::pair<double, Eigen::Vector3d>> by_distance;
  for (const Eigen::Vector3d& p : points) {
    const double d = (p - pivot).norm();
    by_distance.emplace_back(d, d > 0 ? Eigen::Vector3d((p - pivot) / d) : Eigen::Vector3d::Zero());
  }
  std::sort(by_distance.begin(), by_distance.end(),
            [](const auto& a, const auto& b) { return a.first < b.first; });
  SolidSamples samples;
  samples.spacing = spacing;
  for (const auto& [d, u] : by_distance) {
    samples.distance.push_back(d);
    samples.direction.push_back(u);
  }
  return samples;
}

// Whether a turn of at most `degrees` about `pivot` can carry the point at distance `d` in unit
// direction `u` into the solid `samples` fill (or the solid onto the point): some sample at that
// distance within that angle, both widened by the samples' spacing.
bool WithinCap(const SolidSamples& samples, double d, const Eigen::Vector3d& u, double degrees) {
  const double slack = samples.spacing * 0.87;  // half a grid cell's diagonal
  const auto first = std::lower_bound(samples.distance.begin(), samples.distance.end(), d - slack);
  const double widened =
      std::min(M_PI, degrees * kRadiansPerDegree + (d > slack ? std::asin(slack / d) : M_PI));
  const double cos_limit = std::cos(widened);
  for (auto it = first; it != samples.distance.end() && *it <= d + slack; ++it) {
    const std::size_t k = static_cast<std::size_t>(it - samples.distance.begin());
    if (samples.direction[k].dot(u) >= cos_limit) return true;
  }
  return false;
}

}  // namespace

StatusOr<std::vector<int>> SkinReachedAcrossJoints(const TriangleMesh& skin,
                                                   const Skeleton& skeleton,
                                                   const std::vector<BoneSurface>& surfaces,
                                                   const BoneReachOptions& options,
                                                   const CancelToken* cancel) {
  const int n = skin.num_vertices();
  if (surfaces.empty() || n == 0) return std::vector<int>();
  const std::vector<NearestBone> nearest = NearestBones(skin.vertices, skeleton);
  std::vector<Reachable> reachable(surfaces.size());
  for (std::size_t s = 0; s < surfaces.size(); ++s) {
    const Positions& v = surfaces[s].mesh.vertices;
    reachable[s].bvh = std::make_unique<TriangleBvh>(surfaces[s].mesh);
    reachable[s].centre = v.colwise().mean().transpose();
    reachable[s].radius =
        (v.rowwise() - reachable[s].centre.transpose()).rowwise().norm().maxCoeff();
  }
  std::vector<char> reached(static_cast<std::size_t>(n), 0);
  std::vector<RigidTransform> bones(static_cast<std::size_t>(skeleton.num_bones()));
  std::vector<int> candidates;
  for (const int joint : skeleton.InnerJoints()) {
    // The two sides of the joint: the bones starting there turn, the bone carrying it stays.
    std::vector<char> turning(static_cast<std::size_t>(skeleton.num_bones()), 0);
    std::vector<char> side(static_cast<std::size_t>(skeleton.num_bones()), 0);
    for (int k = 0; k < skeleton.num_bones(); ++k) {
      turning[k] = skeleton.bone(k).head_joint == joint ? 1 : 0;
      side[k] = turning[k] != 0 || k == skeleton.IncomingBone(joint) ? 1 : 0;
    }
    const Eigen::Vector3d pivot = skeleton.joint(joint).rest_position;
    const bool sampled = !skeleton.joint(joint).dofs.empty();
    const std::vector<Eigen::Quaterniond> turns =
        sampled ? DegreeOfFreedomTurns(skeleton, joint, options)
                : std::vector<Eigen::Quaterniond>();
    for (std::size_t s = 0; s < surfaces.size(); ++s) {
      DEFORM_RETURN_IF_ERROR(CheckCancelled(cancel, "the bone reach"));
      const BoneSurface& surface = surfaces[s];
      if (side[surface.bone] == 0 && (surface.blend_bone < 0 || side[surface.blend_bone] == 0)) {
        continue;
      }
      const bool surface_turns = turning[surface.bone] != 0;
      const bool blended = surface.blend_bone >= 0 && turning[surface.blend_bone] != surface_turns;
      // Turning about the pivot keeps distances to it: only skin in the shell the surface's ball
      // sweeps, on the other side of the joint (or either side of a surface that half turns), can
      // be reached.
      const double centre_distance = (reachable[s].centre - pivot).norm();
      candidates.clear();
      for (int i = 0; i < n; ++i) {
        if (side[nearest[i].bone] == 0) continue;
        const bool vertex_turns = turning[nearest[i].bone] != 0;
        if (!blended && vertex_turns == surface_turns) continue;
        const double d = (skin.vertices.row(i).transpose() - pivot).norm();
        if (std::abs(d - centre_distance) <= reachable[s].radius) candidates.push_back(i);
      }
      if (candidates.empty()) continue;
      const TriangleBvh& bvh = *reachable[s].bvh;
      if (!sampled) {
        // Every turn of at most max_degrees: the skin on the other side, relative to the surface,
        // turns by that much at most (a blended surface by its share of the turn).
        const SolidSamples samples = SampleSolid(surface, bvh, pivot);
        for (const int i : candidates) {
          if (reached[i] != 0) continue;
          double degrees = options.max_degrees;
          if (blended) {
            const bool vertex_turns = turning[nearest[i].bone] != 0;
            const double share =
                turning[surface.blend_bone] != 0 ? surface.blend : 1 - surface.blend;
            degrees *= vertex_turns == surface_turns ? share : 1 - share;
          }
          const Eigen::Vector3d offset = skin.vertices.row(i).transpose() - pivot;
          const double d = offset.norm();
          if (d > 0 && WithinCap(samples, d, offset / d, degrees)) reached[i] = 1;
        }
        continue;
      }
      for (const Eigen::Quaterniond& turn : turns) {
        const RigidTransform turned{turn, pivot - turn * pivot};
        for (int k = 0; k < skeleton.num_bones(); ++k) {
          bones[k] = turning[k] != 0 ? turned : RigidTransform{};
        }
        const RigidTransform pose = BoneSurfaceTransform(surface, skeleton, bones);
        const Eigen::Quaterniond to_rest = pose.rotation.conjugate();
        for (const int i : candidates) {
          if (reached[i] != 0) continue;
          const Eigen::Vector3d rest = skin.vertices.row(i).transpose();
          const Eigen::Vector3d posed = turning[nearest[i].bone] != 0 ? turned.Apply(rest) : rest;
          const Eigen::Vector3d local = to_rest * (posed - pose.translation);
          if ((local.array() < bvh.lower().array()).any() ||
              (local.array() > bvh.upper().array()).any()) {
            continue;
          }
          if (bvh.Contains(local)) reached[i] = 1;
        }
      }
    }
  }
  std::vector<int> vertices;
  for (int i = 0; i < n; ++i) {
    if (reached[i] != 0) vertices.push_back(i);
  }
  return vertices;
}

Status UnanchorReachedSkin(const TriangleMesh& skin, const Skeleton& skeleton,
                           const std::vector<BoneSurface>& surfaces,
                           const ConstraintOptions& constraints, ModelOptions* model,
                           const CancelToken* cancel) {
  if (surfaces.empty() || !constraints.contacts() || !constraints.bone_reach) {
    return Status::Ok();
  }
  DEFORM_ASSIGN_OR_RETURN(model->unanchored_vertices,
                          SkinReachedAcrossJoints(skin, skeleton, surfaces, {}, cancel));
  return Status::Ok();
}

}  // namespace deform
