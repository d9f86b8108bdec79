#include "core/model/anchors.h"

#include <algorithm>
#include <cmath>

namespace deform {

// The piece of `start` in the rigid zone of its bone (vertices reached through neighbours with
// the same rigid bone); marks them in `seen`.
std::vector<int> RigidPiece(const VertexAdjacency& adjacency, const std::vector<int>& rigid_bone,
                            int start, std::vector<char>* seen) {
  std::vector<int> piece{start};
  (*seen)[start] = 1;
  for (std::size_t q = 0; q < piece.size(); ++q) {
    const int i = piece[q];
    for (int p = adjacency.offsets[i]; p < adjacency.offsets[i + 1]; ++p) {
      const int j = adjacency.neighbors[p];
      if (rigid_bone[j] == rigid_bone[start] && !(*seen)[j]) {
        (*seen)[j] = 1;
        piece.push_back(j);
      }
    }
  }
  return piece;
}

std::vector<int> ChooseAnchors(const VertexAdjacency& adjacency, const std::vector<int>& rigid_bone,
                               const JointRegions& regions, double distance_factor,
                               double min_fraction) {
  const int n = static_cast<int>(rigid_bone.size());
  std::vector<char> seen(n, 0);
  std::vector<int> anchors;
  for (int start = 0; start < n; ++start) {
    if (rigid_bone[start] < 0 || seen[start]) continue;
    std::vector<int> piece = RigidPiece(adjacency, rigid_bone, start, &seen);
    const auto far = std::count_if(piece.begin(), piece.end(), [&](int i) {
      return regions.relative_distance[i] >= distance_factor;
    });
    const auto wanted = std::max<std::ptrdiff_t>(
        1, static_cast<std::ptrdiff_t>(std::ceil(min_fraction * piece.size())));
    const auto count = std::max(far, std::min<std::ptrdiff_t>(wanted, piece.size()));
    // Farthest from the joints first; ties by index, so the choice is deterministic.
    std::partial_sort(piece.begin(), piece.begin() + count, piece.end(), [&](int a, int b) {
      const double da = regions.relative_distance[a], db = regions.relative_distance[b];
      return da > db || (da == db && a < b);
    });
    anchors.insert(anchors.end(), piece.begin(), piece.begin() + count);
  }
  std::sort(anchors.begin(), anchors.end());
  return anchors;
}

}  // namespace deform
