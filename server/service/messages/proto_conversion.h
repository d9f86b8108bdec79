// Conversions between deform.v1 messages and the core's types (no gRPC here, only Protobuf).
//
// Untrusted input is checked and named in INVALID_ARGUMENT / NOT_FOUND messages; nothing here
// asserts on client data. Thread-safe (pure functions).
#pragma once

#include <cstddef>

#include "core/base/status.h"
#include "core/constraints/skin_constraints.h"
#include "core/constraints/tools.h"
#include "core/geometry/skeleton.h"
#include "core/model/deformation_model.h"
#include "core/model/stiffness.h"
#include "deform/v1/deform.pb.h"
#include "service/registry/mesh_registry.h"

namespace deform::service {

// MethodOptions into the model's options. Zero fields mean the defaults (radius factor 1.5,
// materials 4/1/4). Joint radii name joints of `skeleton`. INVALID_ARGUMENT for unknown joints or
// non-finite, non-positive values.
StatusOr<ModelOptions> ModelOptionsFromProto(const v1::MethodOptions& proto,
                                             const Skeleton& skeleton);

// MethodOptions.constraints into the constraints' options: unset fields are on, on and 1e-3;
// contacts off is max_contacts 0 (penetrations are measured, never corrected). INVALID_ARGUMENT
// for a contact_margin that is not finite and in [0, 0.1].
StatusOr<ConstraintOptions> ConstraintOptionsFromProto(const v1::Constraints& proto);
// The options back as the proto states them, every field set.
void ConstraintOptionsToProto(const ConstraintOptions& options, v1::Constraints* proto);

// Tool `index` of a request (a pose's, a contact query's) into the core's Tool, checked by
// ValidateTool against the mesh's rest bounding box [lower, upper]. INVALID_ARGUMENT naming
// "tool <index>" for an unspecified shape, a missing centre (or a capsule's end), or what
// ValidateTool refuses; `tool` is then unspecified.
Status ToolFromProto(const v1::ToolState& state, int index, const Eigen::Vector3d& lower,
                     const Eigen::Vector3d& upper, Tool* tool);

// A StiffnessUpdate into the core's Stiffness for `model`. Zero fields of a joint material mean
// the model's default profile. INVALID_ARGUMENT naming the problem for unknown joints, joints
// without a region, vertex lists of different lengths or out of range, and weights that are not
// finite and in (0, kMaxMaterialWeight]. Vertex indices are the client's (the file's order,
// `client_order` mapping them to solved vertices; empty when the two are the same).
StatusOr<Stiffness> StiffnessFromProto(const v1::StiffnessUpdate& proto,
                                       const DeformationModel& model,
                                       const std::vector<int>& client_order = {});

// The summary of a registered mesh.
void FillMeshSummary(const MeshEntry& entry, v1::MeshSummary* summary);
// Rest positions (float32 xyz) and triangles (uint32, 3 per triangle), little-endian, in the
// client's vertex order (the file's: MeshFileMetadata), and each bone surface's the same way.
void FillMeshGeometry(const MeshEntry& entry, v1::GetMeshInfoResponse* info);

// The bytes of DeformFrame.bone_transforms for `bones`' surfaces (12 float32 each).
std::size_t BoneSurfaceTransformBytes(const BoneContacts* bones);
// DeformFrame.bone_transforms of a frame whose bones moved by `bone_transforms`: per surface
// (BoneSurfaceTransform) its rotation as a row-major 3 x 3 matrix, then its translation, float32
// little-endian, at `out` (BoneSurfaceTransformBytes). Allocation-free.
void EncodeBoneSurfaceTransforms(const BoneContacts& bones, const Skeleton& skeleton,
                                 const std::vector<RigidTransform>& bone_transforms, char* out);

// `count` doubles into `count` float32 little-endian values at `out` (4 * count bytes).
// Allocation-free.
void EncodeFloat32(const double* values, std::size_t count, char* out);
// The xyz rows of `solved_vertices` vertices as float32 in the client's order: row order[f] at
// client vertex f (12 * order.size() bytes), or all rows as they are when `order` is empty.
// Allocation-free.
void EncodeInClientOrder(const double* xyz, int solved_vertices, const std::vector<int>& order,
                         char* out);

}  // namespace deform::service
