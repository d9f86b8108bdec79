#include "core/model/body_binding.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <limits>
#include <utility>

namespace deform {
namespace {

// The rest position at parameter `nearest.parameter` along bone `nearest.bone`.
Eigen::Vector3d PointOnBone(const Skeleton& skeleton, const NearestBone& nearest) {
  const Bone& b = skeleton.bone(nearest.bone);
  const Eigen::Vector3d head = skeleton.joint(b.head_joint).rest_position;
  return head + nearest.parameter * (skeleton.joint(b.tail_joint).rest_position - head);
}

NearestBone MeasureToBone(const Skeleton& skeleton, int bone, const Eigen::Vector3d& p) {
  const Bone& b = skeleton.bone(bone);
  NearestBone result;
  result.bone = bone;
  result.parameter = ClosestSegmentParameter(p, skeleton.joint(b.head_joint).rest_position,
                                             skeleton.joint(b.tail_joint).rest_position);
  result.distance = (PointOnBone(skeleton, result) - p).norm();
  return result;
}

// A vertex whose closest point on `seen` is the bone's head lies behind the joint the bone turns
// about, on its parent's side: it follows the parent bone (and so on up the chain) when it sees the
// parent through the body: the segment to the parent's closest point enters the body (against the
// vertex's outward normal), crosses no surface, and is at most kParentSideReach times as long as
// the one to the head. Without this, skin above a hip whose thigh hangs from a short pelvis segment
// some way off (an explicit parent, RIGS.md) is closer to the thigh's head than to the pelvis and
// follows the thigh: the flank then tears away from the belly when the hip bends.
constexpr double kParentSideReach = 2.0;

NearestBone OnTheParentSide(const Skeleton& skeleton, const TriangleBvh& bvh,
                            const Eigen::Vector3d& p, const Eigen::Vector3d& outward, int vertex,
                            double margin, NearestBone seen, int* tested) {
  for (int depth = 0; depth < skeleton.num_bones() && seen.parameter <= 0; ++depth) {
    const int parent = skeleton.bone(seen.bone).parent_bone;
    if (parent < 0) break;
    const NearestBone candidate = MeasureToBone(skeleton, parent, p);
    if (candidate.distance > kParentSideReach * seen.distance) break;
    const Eigen::Vector3d target = PointOnBone(skeleton, candidate);
    if ((target - p).dot(outward) >= 0) break;
    ++*tested;
    if (bvh.SegmentCrossesSurface(p, target, vertex, margin)) break;
    seen = candidate;
  }
  return seen;
}

// The first of the vertex's nearest bones whose closest point it sees through the body, or a
// NearestBone with bone -1.
NearestBone FirstVisibleBone(const Skeleton& skeleton, const TriangleBvh& bvh,
                             const Eigen::Vector3d& p, const Eigen::Vector3d& outward, int vertex,
                             int max_candidates, double distance_ratio, double margin,
                             std::vector<NearestBone>* candidates, int* tested) {
  candidates->clear();
  for (int k = 0; k < skeleton.num_bones(); ++k) {
    candidates->push_back(MeasureToBone(skeleton, k, p));
  }
  const int count = std::min<int>(max_candidates, static_cast<int>(candidates->size()));
  std::partial_sort(candidates->begin(), candidates->begin() + count, candidates->end(),
                    [](const NearestBone& a, const NearestBone& b) {
                      return a.distance < b.distance ||
                             (a.distance == b.distance && a.bone < b.bone);
                    });
  const double farthest = (*candidates)[0].distance * distance_ratio;
  for (int c = 0; c < count && (*candidates)[c].distance <= farthest; ++c) {
    const NearestBone& candidate = (*candidates)[c];
    ++*tested;
    if (!bvh.SegmentCrossesSurface(p, PointOnBone(skeleton, candidate), vertex, margin)) {
      return OnTheParentSide(skeleton, bvh, p, outward, vertex, margin, candidate, tested);
    }
  }
  return NearestBone{};
}

// Area-weighted vertex normals, pointing out of the enclosed volume (flipped when the triangles
// wind inward: a negative signed volume). Not normalized; zero for an isolated vertex.
Positions OutwardVertexNormals(const TriangleMesh& mesh) {
  Positions normals = Positions::Zero(mesh.num_vertices(), 3);
  double six_volume = 0;
  for (int t = 0; t < mesh.num_triangles(); ++t) {
    const int a = mesh.triangles(t, 0), b = mesh.triangles(t, 1), c = mesh.triangles(t, 2);
    const Eigen::Vector3d pa = mesh.vertices.row(a), pb = mesh.vertices.row(b),
                          pc = mesh.vertices.row(c);
    const Eigen::Vector3d area_normal = (pb - pa).cross(pc - pa);
    six_volume += pa.dot(pb.cross(pc));
    for (int corner : {a, b, c}) normals.row(corner) += area_normal.transpose();
  }
  if (six_volume < 0) normals = -normals;
  return normals;
}

// Gives every vertex with bone -1 the bone of the nearest bound vertex along mesh edges; returns
// how many it reached.
int PropagateAlongSurface(const TriangleMesh& mesh, const VertexAdjacency& adjacency,
                          std::vector<int>* bone) {
  std::vector<int> bound;
  for (int i = 0; i < mesh.num_vertices(); ++i) {
    if ((*bone)[i] >= 0) bound.push_back(i);
  }
  std::vector<int> nearest;
  SurfaceDistances(mesh.vertices, adjacency, bound, &nearest);
  int reached = 0;
  for (int i = 0; i < mesh.num_vertices(); ++i) {
    if ((*bone)[i] < 0 && nearest[i] >= 0) {
      (*bone)[i] = (*bone)[nearest[i]];
      ++reached;
    }
  }
  return reached;
}

}  // namespace

BodyBinding BindThroughBody(const TriangleMesh& mesh, const Skeleton& skeleton,
                            const VertexAdjacency& adjacency, const TriangleBvh& bvh,
                            int max_candidates, double distance_ratio) {
  const int n = mesh.num_vertices();
  const double margin = 1e-7 * BoundingBoxDiagonal(mesh.vertices);
  BodyBinding result;
  std::vector<int> bone(n, -1);
  std::vector<NearestBone> candidates;
  const Positions outward = OutwardVertexNormals(mesh);
  for (int i = 0; i < n; ++i) {
    const NearestBone visible = FirstVisibleBone(
        skeleton, bvh, mesh.vertices.row(i).transpose(), outward.row(i).transpose(), i,
        max_candidates, distance_ratio, margin, &candidates, &result.candidates_tested);
    bone[i] = visible.bone;
    if (visible.bone >= 0) ++result.seen_through_body;
  }
  result.reached_along_surface = PropagateAlongSurface(mesh, adjacency, &bone);
  result.bones.resize(n);
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector3d p = mesh.vertices.row(i).transpose();
    if (bone[i] >= 0) {
      result.bones[i] = MeasureToBone(skeleton, bone[i], p);
      continue;
    }
    // A piece in which no vertex saw a bone: the straight-line nearest (ties to the lower index).
    result.bones[i] = MeasureToBone(skeleton, 0, p);
    for (int k = 1; k < skeleton.num_bones(); ++k) {
      const NearestBone candidate = MeasureToBone(skeleton, k, p);
      if (candidate.distance < result.bones[i].distance) result.bones[i] = candidate;
    }
    ++result.straight_line;
  }
  return result;
}

}  // namespace deform
