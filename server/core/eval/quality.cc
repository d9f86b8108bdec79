#include "core/eval/quality.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <unordered_map>

#include "core/eval/triangle_counts.h"
#include "core/geometry/skeleton_geometry.h"

namespace deform {

ClearanceStats SkinClearance(const Positions& rest, const Positions& posed,
                             const Skeleton& skeleton, const std::vector<RigidTransform>& bones) {
  const double tiny = 1e-9 * BoundingBoxDiagonal(rest);
  std::vector<double> ratios;
  ratios.reserve(rest.rows());
  for (int i = 0; i < rest.rows(); ++i) {
    double rest_distance = std::numeric_limits<double>::infinity();
    double posed_distance = std::numeric_limits<double>::infinity();
    for (int k = 0; k < skeleton.num_bones(); ++k) {
      const Eigen::Vector3d& a = skeleton.joint(skeleton.bone(k).head_joint).rest_position;
      const Eigen::Vector3d& b = skeleton.joint(skeleton.bone(k).tail_joint).rest_position;
      rest_distance = std::min(rest_distance, PointSegmentDistance(rest.row(i).transpose(), a, b));
      posed_distance = std::min(
          posed_distance,
          PointSegmentDistance(posed.row(i).transpose(), bones[k].Apply(a), bones[k].Apply(b)));
    }
    if (rest_distance > tiny) ratios.push_back(posed_distance / rest_distance);
  }
  ClearanceStats stats;
  if (ratios.empty()) return stats;
  std::sort(ratios.begin(), ratios.end());
  stats.min = ratios.front();
  stats.p01 = ratios[static_cast<size_t>(0.01 * (ratios.size() - 1))];
  stats.sink_fraction =
      static_cast<double>(std::lower_bound(ratios.begin(), ratios.end(), 0.5) - ratios.begin()) /
      ratios.size();
  return stats;
}

QualityReport MeasureQuality(const TriangleMesh& rest_mesh, const Positions& posed,
                             const Skeleton& skeleton, const std::vector<RigidTransform>& bones,
                             const Positions& skinned, const std::vector<int>& rigid_bone,
                             const BoneContacts* bone_surfaces) {
  QualityReport report;
  const double diagonal = BoundingBoxDiagonal(rest_mesh.vertices);
  const double rest_volume = EnclosedVolume(rest_mesh.vertices, rest_mesh.triangles);
  report.volume_change = (EnclosedVolume(posed, rest_mesh.triangles) - rest_volume) / rest_volume;
  report.clearance = SkinClearance(rest_mesh.vertices, posed, skeleton, bones);
  for (int i = 0; i < rest_mesh.num_vertices(); ++i) {
    if (rigid_bone[i] < 0) continue;
    report.rigid_zone_error =
        std::max(report.rigid_zone_error, (posed.row(i) - skinned.row(i)).norm() / diagonal);
  }
  report.max_displacement = (posed - rest_mesh.vertices).rowwise().norm().maxCoeff() / diagonal;
  if (bone_surfaces != nullptr) report.bone_penetration = bone_surfaces->Measure(posed, bones);
  report.inverted_triangles =
      CountInvertedTriangles(rest_mesh.triangles, rest_mesh.vertices, posed, skinned);
  report.self_intersections = CountSelfIntersections(rest_mesh.triangles, posed);
  return report;
}

}  // namespace deform
