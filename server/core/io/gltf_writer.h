// Writing a skinned glTF 2.0 rig (.gltf with one base64 data-URI buffer, or .glb) from the core's
// mesh, skeleton and skinning weights: what ReadGltf (rig_import.h) reads back, for exporting a
// rig and for tests that make their own glTF files.
//
// Layout written: one node per skeleton joint (named after it, translated from its parent joint,
// no rotation), a joint's parent being the head joint of its incoming bone; one skin over all
// joints in skeleton order, with inverse bind matrices (translation by -rest position); one mesh
// node with one triangle primitive: POSITION (float), indices (unsigned int), JOINTS_n (unsigned
// byte, or short beyond 256 joints) and WEIGHTS_n (float), n = 0.. as many sets of four as the
// vertex with most influences needs.
//
// Bone surfaces, when given: one mesh node each (named after the surface; positions, indices),
// a child of its bone's head joint node, so that ReadGltf takes them back as bone surfaces (on the
// bone starting at that joint; a blend bone has no glTF form and is not written).
//
// Weights are per bone; glTF's are per joint. A bone's weight is written on its head joint (the
// joint whose rotation moves it), so bones that share a head joint share one influence: ReadGltf
// then gives it to the nearest of them. Positions are written as floats (about 7 digits).
#pragma once

#include <string>
#include <vector>

#include "core/base/status.h"
#include "core/geometry/bone_surface.h"
#include "core/geometry/mesh.h"
#include "core/geometry/skeleton.h"
#include "core/geometry/skin_weights.h"

namespace deform {

enum class GltfContainer {
  kGltf,  // JSON text, the buffer as a data URI
  kGlb,   // binary: a JSON chunk and a BIN chunk
};

// The file's bytes. INVALID_ARGUMENT when the weights do not fit the mesh and skeleton
// (NormalizeSkinWeights) or the mesh's indices are out of range; RESOURCE_EXHAUSTED beyond 65,536
// joints.
// Bone surfaces invalid for `skeleton` (ValidateBoneSurfaces) are INVALID_ARGUMENT.
StatusOr<std::string> WriteGltf(const TriangleMesh& mesh, const Skeleton& skeleton,
                                const SkinWeights& weights, GltfContainer container,
                                const std::vector<BoneSurface>& bone_surfaces = {});

// Writes a file; the container comes from the extension (.gltf or .glb). NOT_FOUND when the folder
// does not exist.
Status WriteGltfFile(const std::string& path, const TriangleMesh& mesh, const Skeleton& skeleton,
                     const SkinWeights& weights,
                     const std::vector<BoneSurface>& bone_surfaces = {});

}  // namespace deform
