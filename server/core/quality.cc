#include "core/quality.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <unordered_map>

#include "core/skeleton_geometry.h"

namespace deform {
namespace {

double SignedTetraVolume(const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                         const Eigen::Vector3d& c) {
  return a.dot(b.cross(c)) / 6.0;
}

int FindRoot(std::vector<int>& parent, int x) {
  while (parent[x] != x) x = parent[x] = parent[parent[x]];
  return x;
}

}  // namespace

double EnclosedVolume(const Positions& positions, const Triangles& triangles) {
  auto point = [&](int i) -> Eigen::Vector3d { return positions.row(i).transpose(); };
  double volume = 0;
  // Directed edges: an edge seen once (its reverse absent) lies on the boundary.
  std::unordered_map<std::int64_t, int> directed;
  auto key = [](int a, int b) { return (static_cast<std::int64_t>(a) << 32) | static_cast<unsigned>(b); };
  for (int f = 0; f < triangles.rows(); ++f) {
    volume += SignedTetraVolume(point(triangles(f, 0)), point(triangles(f, 1)), point(triangles(f, 2)));
    for (int c = 0; c < 3; ++c) directed[key(triangles(f, c), triangles(f, (c + 1) % 3))]++;
  }
  std::vector<std::pair<int, int>> boundary;
  for (int f = 0; f < triangles.rows(); ++f) {
    for (int c = 0; c < 3; ++c) {
      const int a = triangles(f, c), b = triangles(f, (c + 1) % 3);
      if (directed.find(key(b, a)) == directed.end()) boundary.emplace_back(a, b);
    }
  }
  if (boundary.empty()) return volume;
  // Group boundary edges into loops and close each with a fan from its centroid.
  std::vector<int> parent(positions.rows());
  std::iota(parent.begin(), parent.end(), 0);
  for (const auto& [a, b] : boundary) parent[FindRoot(parent, a)] = FindRoot(parent, b);
  std::unordered_map<int, std::pair<Eigen::Vector3d, int>> centroid;
  for (const auto& [a, b] : boundary) {
    for (int v : {a, b}) {
      auto& entry = centroid.try_emplace(FindRoot(parent, v), Eigen::Vector3d::Zero(), 0).first->second;
      entry.first += point(v);
      entry.second += 1;
    }
  }
  for (const auto& [a, b] : boundary) {
    const auto& entry = centroid[FindRoot(parent, a)];
    const Eigen::Vector3d c = entry.first / entry.second;
    volume += SignedTetraVolume(c, point(b), point(a));
  }
  return volume;
}

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
      posed_distance = std::min(posed_distance,
                                PointSegmentDistance(posed.row(i).transpose(), bones[k].Apply(a),
                                                     bones[k].Apply(b)));
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
                             const std::vector<int>& rigid_vertices,
                             const std::vector<int>& rigid_bones) {
  QualityReport report;
  const double diagonal = BoundingBoxDiagonal(rest_mesh.vertices);
  const double rest_volume = EnclosedVolume(rest_mesh.vertices, rest_mesh.triangles);
  report.volume_change = (EnclosedVolume(posed, rest_mesh.triangles) - rest_volume) / rest_volume;
  report.clearance = SkinClearance(rest_mesh.vertices, posed, skeleton, bones);
  for (size_t a = 0; a < rigid_vertices.size(); ++a) {
    const int i = rigid_vertices[a];
    const Eigen::Vector3d target = bones[rigid_bones[a]].Apply(rest_mesh.vertices.row(i).transpose());
    report.rigid_zone_error =
        std::max(report.rigid_zone_error, (posed.row(i).transpose() - target).norm() / diagonal);
  }
  report.max_displacement = (posed - rest_mesh.vertices).rowwise().norm().maxCoeff() / diagonal;
  return report;
}

}  // namespace deform
