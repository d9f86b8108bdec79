// Rigs on which binding each vertex to the straight-line nearest bone is wrong, built from the
// knee phantom: a part of one limb lying close to another limb's bone.
#pragma once

#include <gtest/gtest.h>

#include <string>
#include <utility>
#include <vector>

#include "core/geometry/mesh.h"
#include "core/geometry/skeleton.h"
#include "core/io/phantom.h"

namespace deform::test_support {

struct Rig {
  TriangleMesh mesh;
  Skeleton skeleton;
  int first_leg_vertices = 0;  // vertices [0, first_leg_vertices) are leg A's, the rest leg B's
};

// Two phantom legs side by side along +X with `gap` between them at the widest (the hip), leg B's
// skeleton moved `bone_offset` toward leg A (still inside leg B). Leg A's skin facing leg B is then
// nearer to leg B's bones than to its own. Joints of leg B are named "<name>_b".
inline Rig TwoLegsSideBySide(int vertices_per_leg = 1200, double gap = 0.1,
                             double bone_offset = 0.3) {
  auto phantom = MakeKneePhantom(vertices_per_leg);
  EXPECT_TRUE(phantom.ok());
  const TriangleMesh& leg = phantom->mesh;
  const double widest = leg.vertices.col(0).maxCoeff() - leg.vertices.col(0).minCoeff();
  const Eigen::RowVector3d shift(widest + gap, 0, 0);
  Rig rig;
  const int n = leg.num_vertices();
  rig.first_leg_vertices = n;
  rig.mesh.vertices.resize(2 * n, 3);
  rig.mesh.vertices.topRows(n) = leg.vertices;
  rig.mesh.vertices.bottomRows(n) = leg.vertices.rowwise() + shift;
  rig.mesh.triangles.resize(2 * leg.num_triangles(), 3);
  rig.mesh.triangles.topRows(leg.num_triangles()) = leg.triangles;
  rig.mesh.triangles.bottomRows(leg.num_triangles()) = leg.triangles.array() + n;

  const Skeleton& skeleton = phantom->skeleton;
  std::vector<Joint> joints = skeleton.joints();
  std::vector<std::pair<int, int>> bones;
  for (const Bone& bone : skeleton.bones()) bones.emplace_back(bone.head_joint, bone.tail_joint);
  const int joint_count = skeleton.num_joints();
  for (int j = 0; j < joint_count; ++j) {
    Joint copy = skeleton.joint(j);
    copy.name += "_b";
    copy.rest_position += (shift.transpose() - Eigen::Vector3d(bone_offset, 0, 0));
    joints.push_back(copy);
  }
  for (const Bone& bone : skeleton.bones()) {
    bones.emplace_back(bone.head_joint + joint_count, bone.tail_joint + joint_count);
  }
  auto combined = Skeleton::Create(std::move(joints), std::move(bones));
  EXPECT_TRUE(combined.ok()) << combined.status().ToString();
  rig.skeleton = std::move(*combined);
  return rig;
}

}  // namespace deform::test_support
