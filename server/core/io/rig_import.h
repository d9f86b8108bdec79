// Importing a skinned rig from glTF 2.0 (.gltf with data URIs, or .glb): the mesh, the skeleton
// and the skinning weights together, ready for the deformation model.
//
// Untrusted input: no bytes crash the reader, and reading never touches anything but the bytes
// given (a .gltf that refers to an external file, buffer or image, is INVALID_ARGUMENT naming the
// URI; data URIs and a .glb's BIN chunk are read). Malformed content is INVALID_ARGUMENT naming
// the problem (accessor, primitive, node); sizes beyond MeshLimits are RESOURCE_EXHAUSTED.
//
// What is read, and how it maps onto the core's types:
//   - The skinned mesh: every node with both "mesh" and "skin" (none: INVALID_ARGUMENT "no
//     skin: ..."), their meshes concatenated in node-index order (`skinned_nodes` says which file
//     vertices each node holds), each mesh's primitives in file order. Every primitive must be
//     triangles (mode 4, indexed or not) with POSITION (float VEC3) and JOINTS_n/WEIGHTS_n pairs
//     (n = 0, 1, ...; JOINTS unsigned byte/short, WEIGHTS float or normalized unsigned
//     byte/short). Morph targets, normals, UVs and materials are ignored. Mesh nodes without a
//     skin are not part of the skinned mesh.
//   - Positions are kept as the file holds them, in the bind space the inverse bind matrices refer
//     to: glTF ignores a skinned mesh node's own transform (the joints place the mesh), so it is
//     not applied here either.
//   - Joints: the union of the skins' joints by node (the first skinned node's skin in its order,
//     then each later skin's new joints). Several skins must bind the shared joints in one pose,
//     up to one transform per skin that maps its mesh into the first skin's bind space (applied
//     to that node's positions); otherwise INVALID_ARGUMENT naming the node. Joints are
//     named after their nodes ("node<index>" when unnamed; a repeated name gets "_2", "_3"...). A
//     joint's bind position is the translation of the inverse of its inverse bind matrix; without
//     inverseBindMatrices, the translation of its node's world transform. Its parent is the nearest
//     ancestor node that is also a skin joint.
//   - Bones: one per (parent joint -> child joint). A joint within 1e-6 of the mesh's bounding-box
//     diagonal of its parent joint is merged into it (same skeleton joint; its weights go to the
//     parent's bones). A joint that heads no bone but has weighted vertices gets an end joint
//     "<name>_end", half the parent bone's length further along the parent->joint direction (a
//     lone joint without parent: toward its vertices' weighted centroid, twice as far, or along
//     their principal direction when they centre on the joint).
//   - Weights: a glTF joint's weight goes to the bone that starts at its skeleton joint; where
//     several start there, to the one nearest the vertex; normalized (NormalizeSkinWeights).
//   - Bone surfaces: mesh nodes without a skin that a joint carries (the joint's node or a
//     descendant of it) and that are bones: closed, inside the skin, not entered by it at rest
//     (internal/gltf_bone_nodes.h has the whole rule). Each goes on the bone that starts at its
//     joint; a node left out (a prop: a sword, eyes, a helmet) gets a line in `warnings`.
//   - Welding: vertices that glTF splits at seams (exactly equal position, weights equal within
//     1e-6) become one vertex of the mesh; vertices no triangle uses are dropped from it, and each
//     follows the used vertex before it in the file (the first used one, for those before it):
//     frames give it that vertex's position, so an engine's whole vertex buffer stays defined.
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include "core/base/status.h"
#include "core/geometry/bone_surface.h"
#include "core/geometry/mesh.h"
#include "core/geometry/skeleton.h"
#include "core/geometry/skin_weights.h"

namespace deform {

// The file vertices [first_file_vertex, first_file_vertex + num_file_vertices) come from the
// skinned mesh node `node` (its glTF node index; `name` its name or "node<index>").
struct SkinnedNodeRange {
  int node = -1;
  std::string name;
  int first_file_vertex = 0;
  int num_file_vertices = 0;
};

struct RigImport {
  TriangleMesh mesh;    // the welded mesh the solve uses (validated with ValidateMesh)
  Skeleton skeleton;    // the skin's joints (plus any "<name>_end" joints) and their bones
  SkinWeights weights;  // on the welded vertices, bone indices in skeleton bone order; normalized
  // For each vertex in the file's own order (all primitives of the skinned mesh concatenated, as
  // an engine holds them): its vertex in `mesh` (always one: a vertex no triangle uses follows
  // the used vertex before it, see Welding above). Frames computed on `mesh` return to the file's
  // order through this.
  std::vector<int> file_vertex_to_mesh;
  std::vector<int> unused_file_vertices;        // file vertices no triangle uses, ascending
  std::vector<SkinnedNodeRange> skinned_nodes;  // in file vertex order, one per skinned node
  // The file's bone surfaces (see above), in node order, in `mesh`'s space and on `skeleton`'s
  // bones; valid (ValidateBoneSurfaces).
  std::vector<BoneSurface> bone_surfaces;
  // What a user should know of the file, one line each: which file vertices each skinned node
  // holds (when there are several), mesh nodes under joints not taken as bone surfaces, and a scale
  // implausible in metres (a bounding-box diagonal outside kPlausibleDiagonalMetres for a limb or a
  // character: often a file in centimetres).
  std::vector<std::string> warnings;
  std::string units = "metre";  // glTF's units (the spec says metres)
  std::string up_axis = "+Y";   // glTF's up axis
};

// The bounding-box diagonals, in metres, of a plausible limb or character: a skinned mesh outside
// gets a warning in RigImport::warnings.
inline constexpr double kPlausibleDiagonalMetres[2] = {0.01, 10.0};

// Parses a whole .gltf (JSON, buffers as data URIs) or .glb (told by its "glTF" magic) held in
// memory. The vertex limit applies to the file's vertices before welding, the triangle limit to
// its triangles.
StatusOr<RigImport> ReadGltf(std::string_view bytes, const MeshLimits& limits = {});
// Reads a file (.gltf or .glb; the content decides). NOT_FOUND if it cannot be opened; errors
// carry the path.
StatusOr<RigImport> ReadGltfFile(const std::string& path, const MeshLimits& limits = {});

// True for a path ending in .gltf or .glb (case-insensitive).
bool IsGltfPath(std::string_view path);

}  // namespace deform
