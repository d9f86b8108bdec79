// Conversions between deform.v1 messages and the core's types (no gRPC here, only Protobuf).
//
// Untrusted input is checked and named in INVALID_ARGUMENT / NOT_FOUND messages; nothing here
// asserts on client data. Thread-safe (pure functions).
#pragma once

#include <cstddef>

#include "core/base/status.h"
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
// client's vertex order (the file's: MeshFileMetadata).
void FillMeshGeometry(const MeshEntry& entry, v1::GetMeshInfoResponse* info);

// `count` doubles into `count` float32 little-endian values at `out` (4 * count bytes).
// Allocation-free.
void EncodeFloat32(const double* values, std::size_t count, char* out);
// The xyz rows of `solved_vertices` vertices as float32 in the client's order: row order[f] at
// client vertex f (12 * order.size() bytes), or all rows as they are when `order` is empty.
// Allocation-free.
void EncodeInClientOrder(const double* xyz, int solved_vertices, const std::vector<int>& order,
                         char* out);

}  // namespace deform::service
