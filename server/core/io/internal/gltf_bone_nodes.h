// Internal to the glTF import: the bone surfaces a character carries as mesh nodes of its own (a
// femur modelled inside the thigh and parented to the thigh's joint), found and checked.
//
// A candidate is every node with a mesh and no skin that is a skin joint or has one among its
// ancestors (the nearest such joint carries it). Its primitives are read as the skinned mesh's are
// (triangles with POSITION; influences ignored), placed in the skinned mesh's bind space through
// its joint (bind(joint) * world(joint)^-1 * world(node): the file's scene may hold another pose
// than the bind pose), seam copies welded by exact position, and oriented outward.
//
// Characters also parent props to joints (a sword in a hand, eyes in a head, a helmet), so a
// candidate is taken as a bone surface only when it is one: closed, with a positive volume, every
// vertex inside the skin (an open skin closed by a fan at each boundary loop), and no skin vertex
// inside it at rest. Every other candidate is left out with a warning line naming the node and
// the reason; nothing about a candidate makes the import fail.
#pragma once

#include <string>
#include <vector>

#include "core/geometry/bone_surface.h"
#include "core/geometry/mesh.h"
#include "gltf_character.h"
#include "gltf_rig_skeleton.h"
#include "gltf_scene.h"
#include "tiny_gltf.h"

namespace deform::gltf_internal {

struct BoneNodeMesh {
  int node = -1;
  std::string name;   // the node's name, "node<index>" when it has none
  int joint = -1;     // the carrying joint: an index into CharacterMesh::joints
  TriangleMesh mesh;  // bind space, welded, oriented outward when it is closed
};

// Every candidate's mesh, read and placed; a candidate that cannot be read (a malformed primitive,
// a singular transform, beyond `limits` or `bone_limits`) gets a line in `warnings` instead.
std::vector<BoneNodeMesh> ReadBoneNodeMeshes(const tinygltf::Model& model, const SceneNodes& scene,
                                             const CharacterMesh& character,
                                             const MeshLimits& limits,
                                             const BoneSurfaceLimits& bone_limits,
                                             std::vector<std::string>* warnings);

// The candidates that are bones (see above) as bone surfaces of `rig`, each on the bone that starts
// at its joint (the nearest to its centroid where several do; a joint heading none passes to its
// parent joint's). `joints` are the character's joints, `skin` the welded skinned mesh.
std::vector<BoneSurface> SelectBoneSurfaces(std::vector<BoneNodeMesh> candidates,
                                            const std::vector<SkinJoint>& joints,
                                            const RigSkeleton& rig, const TriangleMesh& skin,
                                            std::vector<std::string>* warnings);

}  // namespace deform::gltf_internal
