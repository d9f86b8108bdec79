// Rigs on which binding each vertex to the straight-line nearest bone is wrong: a part of one limb
// lying close to another limb's bone (two legs side by side, two fingers of one palm, an ear
// hanging beside an arm).
#pragma once

#include <gtest/gtest.h>

#include <set>
#include <string>
#include <utility>
#include <vector>

#include "core/geometry/mesh.h"
#include "core/geometry/skeleton.h"
#include "core/io/phantom.h"
#include "tests/core/model/voxel_mesh.h"

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

// A joint at `position` with no named degree of freedom: poses turn it about the rest frame's x, y
// and z (as TGF joints).
inline Joint FreeJoint(const std::string& name, const Eigen::Vector3d& position) {
  Joint joint;
  joint.name = name;
  joint.rest_position = position;
  return joint;
}

inline Skeleton MakeSkeleton(std::vector<Joint> joints, std::vector<std::pair<int, int>> bones) {
  auto skeleton = Skeleton::Create(std::move(joints), std::move(bones));
  EXPECT_TRUE(skeleton.ok()) << skeleton.status().ToString();
  return std::move(*skeleton);
}

// A palm (7 x 6 x 2 units) with two fingers (3 x 12 x 2 each, one unit apart) along +y, bending
// about x. Finger B's bones run 1.2 units toward finger A (still inside B), so the side of finger
// A facing B is nearer to B's bones than to A's own. `resolution` cells per unit. Joints: wrist,
// palm, knuckle_a, middle_a, tip_a, knuckle_b, middle_b, tip_b.
inline Rig TwoFingersOfOnePalm(int resolution = 2) {
  std::set<Cell> cells;
  const int r = resolution;
  AddBox(&cells, {0, 0, 0}, {7 * r, 6 * r, 2 * r});
  AddBox(&cells, {0, 6 * r, 0}, {3 * r, 18 * r, 2 * r});
  AddBox(&cells, {4 * r, 6 * r, 0}, {7 * r, 18 * r, 2 * r});
  Rig rig;
  rig.mesh = VoxelMesh(cells, 1.0 / r);
  const double a = 1.5, b = 5.5 - 1.2;
  rig.skeleton =
      MakeSkeleton({FreeJoint("wrist", {3.5, 0.5, 1}), FreeJoint("palm", {3.5, 5, 1}),
                    FreeJoint("knuckle_a", {a, 6.5, 1}), FreeJoint("middle_a", {a, 12, 1}),
                    FreeJoint("tip_a", {a, 17.5, 1}), FreeJoint("knuckle_b", {b, 6.5, 1}),
                    FreeJoint("middle_b", {b, 12, 1}), FreeJoint("tip_b", {b, 17.5, 1})},
                   {{0, 1}, {1, 2}, {2, 3}, {3, 4}, {1, 5}, {5, 6}, {6, 7}});
  return rig;
}

// A head (6 x 6 x 6 units, its bone inside) with an ear: a flap one unit thick hanging 8 units
// down from the head's side, one unit beside an arm (a separate closed piece, 3 x 14 x 3, whose
// bones run 1.2 units toward the ear). The ear's lower part is far nearer to the arm's bones than
// to the head's. Joints: neck, crown (the head's bone), shoulder, elbow, wrist.
inline Rig EarBesideAnArm(int resolution = 2) {
  std::set<Cell> cells;
  const int r = resolution;
  AddBox(&cells, {0, 14 * r, 0}, {6 * r, 20 * r, 6 * r});         // head
  AddBox(&cells, {6 * r, 6 * r, 2 * r}, {7 * r, 16 * r, 4 * r});  // ear
  AddBox(&cells, {8 * r, 0, 1 * r}, {11 * r, 14 * r, 4 * r});     // arm
  Rig rig;
  rig.mesh = VoxelMesh(cells, 1.0 / r);
  const double arm_x = 9.5 - 1.2;
  rig.skeleton =
      MakeSkeleton({FreeJoint("neck", {3, 14.5, 3}), FreeJoint("crown", {3, 19.5, 3}),
                    FreeJoint("shoulder", {arm_x, 13.5, 2.5}), FreeJoint("elbow", {arm_x, 7, 2.5}),
                    FreeJoint("wrist", {arm_x, 0.5, 2.5})},
                   {{0, 1}, {2, 3}, {3, 4}});
  return rig;
}

}  // namespace deform::test_support
