#include "core/model/binding_report.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <limits>
#include <queue>
#include <set>
#include <string>
#include <utility>

#include "core/base/median.h"
#include "core/model/anchors.h"

namespace deform {
namespace {

std::string Format(const char* format, double value) {
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, format, value);
  return buffer;
}

std::string BoneName(const Skeleton& skeleton, int bone) {
  return skeleton.joint(skeleton.bone(bone).head_joint).name + "->" +
         skeleton.joint(skeleton.bone(bone).tail_joint).name;
}

double DistanceToBone(const Skeleton& skeleton, int bone, const Eigen::Vector3d& p) {
  const Bone& b = skeleton.bone(bone);
  return PointSegmentDistance(p, skeleton.joint(b.head_joint).rest_position,
                              skeleton.joint(b.tail_joint).rest_position);
}

// The connected pieces of bone `bone`'s rigid zone, largest first.
std::vector<std::vector<int>> Pieces(const VertexAdjacency& adjacency,
                                     const std::vector<int>& rigid_bone, int bone,
                                     std::vector<char>* seen) {
  std::vector<std::vector<int>> pieces;
  for (int start = 0; start < static_cast<int>(rigid_bone.size()); ++start) {
    if (rigid_bone[start] == bone && !(*seen)[start]) {
      pieces.push_back(RigidPiece(adjacency, rigid_bone, start, seen));
    }
  }
  std::sort(pieces.begin(), pieces.end(),
            [](const auto& a, const auto& b) { return a.size() > b.size(); });
  return pieces;
}

void ReportBone(const TriangleMesh& mesh, const Skeleton& skeleton,
                const VertexAdjacency& adjacency, const std::vector<int>& bound_bone,
                const std::vector<int>& rigid_bone, double diagonal, std::vector<char>* seen,
                BoneBinding* report, std::vector<std::string>* warnings) {
  const int k = report->bone;
  std::vector<double> distances;
  for (int i = 0; i < mesh.num_vertices(); ++i) {
    if (bound_bone[i] != k) continue;
    ++report->vertices;
    report->rigid_vertices += rigid_bone[i] == k;
    distances.push_back(DistanceToBone(skeleton, k, mesh.vertices.row(i).transpose()));
  }
  report->thickness = 2 * Median(distances);
  for (double d : distances) report->beyond_thickness += d > 2 * report->thickness;

  const std::vector<std::vector<int>> pieces = Pieces(adjacency, rigid_bone, k, seen);
  for (const auto& piece : pieces) report->pieces.push_back(static_cast<int>(piece.size()));
  if (pieces.size() > 1) {
    const std::vector<double> along = SurfaceDistances(mesh.vertices, adjacency, pieces.front());
    for (std::size_t p = 1; p < pieces.size(); ++p) {
      double gap = std::numeric_limits<double>::infinity();
      for (int i : pieces[p]) gap = std::min(gap, along[i]);
      report->farthest_piece = std::max(report->farthest_piece, gap);
    }
  }
  // Toes or fingers split by a joint region lie a few limb widths apart along the surface; a part
  // bound to the wrong bone (an ear to a hand) lies across the body.
  const double far_apart = std::max(2 * report->thickness, 0.2 * diagonal);
  if (pieces.size() > 1 && report->farthest_piece > far_apart) {
    const std::string how_far =
        std::isfinite(report->farthest_piece)
            ? Format("%.3g", report->farthest_piece / diagonal) + " diagonals along the surface"
            : std::string("not connected by the surface");
    warnings->push_back("bone " + report->name + ": its rigid zone falls into " +
                        std::to_string(pieces.size()) + " pieces, one " + how_far +
                        " from the largest (a part bound to the wrong bone?)");
  }
  if (report->vertices == 0) {
    warnings->push_back("bone " + report->name + ": no vertex follows it");
  } else if (report->rigid_vertices > 0 && report->beyond_thickness > 0) {
    warnings->push_back("bone " + report->name + ": " + std::to_string(report->beyond_thickness) +
                        " of its " + std::to_string(report->vertices) +
                        " vertices lie farther from it than twice the limb's thickness (" +
                        Format("%.3g", 2 * report->thickness) + ")");
  }
}

}  // namespace

Status CheckSkeletonAgainstMesh(const TriangleMesh& mesh, const Skeleton& skeleton,
                                const TriangleBvh& bvh) {
  const double diagonal = BoundingBoxDiagonal(mesh.vertices);
  const Eigen::Vector3d lower =
      mesh.vertices.colwise().minCoeff().transpose().array() - 0.01 * diagonal;
  const Eigen::Vector3d upper =
      mesh.vertices.colwise().maxCoeff().transpose().array() + 0.01 * diagonal;
  bool any_inside_box = false;
  for (const Joint& joint : skeleton.joints()) {
    const Eigen::Vector3d& p = joint.rest_position;
    any_inside_box |= (p.array() >= lower.array()).all() && (p.array() <= upper.array()).all();
    const double distance = bvh.DistanceToSurface(p);
    if (distance > diagonal) {
      return Status::InvalidArgument(
          "joint '" + joint.name + "' lies " + Format("%.3g", distance / diagonal) +
          " mesh diagonals from the mesh's surface: the skeleton does not belong to this mesh "
          "(same units and placement?)");
    }
  }
  if (!any_inside_box) {
    return Status::InvalidArgument(
        "no joint of the skeleton lies within the mesh's bounding box: the skeleton does not "
        "belong to this mesh (same units and placement?)");
  }
  return Status::Ok();
}

namespace {

// A warning for each connected piece of the mesh whose vertices follow bones of more than one tree
// of the skeleton: a tree's root joint then turns its part with no joint region between them (a
// crease), as when a TGF file's bones do not join a hip to the pelvis.
void ReportSeparateTrees(const Skeleton& skeleton, const VertexAdjacency& adjacency,
                         const std::vector<int>& bound_bone, std::vector<std::string>* warnings) {
  std::vector<int> root_joint(skeleton.num_bones(), -1);
  for (int k : skeleton.BonesParentsFirst()) {
    const Bone& bone = skeleton.bone(k);
    root_joint[k] = bone.parent_bone < 0 ? bone.head_joint : root_joint[bone.parent_bone];
  }
  std::vector<int> component;
  const int count = ConnectedComponents(adjacency, &component);
  std::vector<std::set<int>> roots(count);
  std::vector<int> size(count, 0);
  for (std::size_t i = 0; i < component.size(); ++i) {
    ++size[component[i]];
    if (bound_bone[i] >= 0) roots[component[i]].insert(root_joint[bound_bone[i]]);
  }
  for (int c = 0; c < count; ++c) {
    if (roots[c].size() < 2) continue;
    std::string names;
    for (int joint : roots[c]) {
      if (names.size() > 200) {
        names += ", ...";
        break;
      }
      names += (names.empty() ? "'" : ", '") + skeleton.joint(joint).name + "'";
    }
    warnings->push_back("one connected piece of the mesh (" + std::to_string(size[c]) +
                        " vertices) follows " + std::to_string(roots[c].size()) +
                        " separate skeleton trees (root joints " + names +
                        "): a root joint's rotation has no joint region there; join the trees "
                        "with bones");
  }
}

}  // namespace

BindingReport ReportBinding(const TriangleMesh& mesh, const Skeleton& skeleton,
                            const VertexAdjacency& adjacency, const TriangleBvh& bvh,
                            const std::vector<int>& bound_bone, const std::vector<int>& rigid_bone,
                            const std::vector<int>& anchors, bool closed) {
  const double diagonal = BoundingBoxDiagonal(mesh.vertices);
  BindingReport report;
  std::vector<char> seen(mesh.num_vertices(), 0);
  for (int k = 0; k < skeleton.num_bones(); ++k) {
    BoneBinding bone;
    bone.bone = k;
    bone.name = BoneName(skeleton, k);
    ReportBone(mesh, skeleton, adjacency, bound_bone, rigid_bone, diagonal, &seen, &bone,
               &report.warnings);
    report.bones.push_back(std::move(bone));
  }
  for (int a : anchors) {
    if (rigid_bone[a] >= 0) ++report.bones[rigid_bone[a]].anchors;
  }
  ReportSeparateTrees(skeleton, adjacency, bound_bone, &report.warnings);
  for (const Joint& joint : skeleton.joints()) {
    const double distance = bvh.DistanceToSurface(joint.rest_position);
    const bool outside = closed ? !bvh.Contains(joint.rest_position) : false;
    if (outside && distance > 0.01 * diagonal) {
      report.joints_outside.push_back(joint.name);
      report.warnings.push_back("joint '" + joint.name + "' lies outside the mesh, " +
                                Format("%.3g", distance / diagonal) +
                                " diagonals from its surface");
    } else if (!closed && distance > 0.25 * diagonal) {
      report.warnings.push_back("joint '" + joint.name + "' lies " +
                                Format("%.3g", distance / diagonal) +
                                " diagonals from the mesh's surface");
    }
  }
  return report;
}

}  // namespace deform
