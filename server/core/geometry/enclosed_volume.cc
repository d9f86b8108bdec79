#include "core/geometry/enclosed_volume.h"

#include <Eigen/Geometry>
#include <cstdint>
#include <numeric>
#include <unordered_map>
#include <utility>
#include <vector>

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
  auto key = [](int a, int b) {
    return (static_cast<std::int64_t>(a) << 32) | static_cast<unsigned>(b);
  };
  for (int f = 0; f < triangles.rows(); ++f) {
    volume +=
        SignedTetraVolume(point(triangles(f, 0)), point(triangles(f, 1)), point(triangles(f, 2)));
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
      auto& entry =
          centroid.try_emplace(FindRoot(parent, v), Eigen::Vector3d::Zero(), 0).first->second;
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

}  // namespace deform
