// Checks that the mesh deformd loaded is the local reference's: the same vertex, triangle and bone
// counts, the same kind of binding, and the same rest positions vertex for vertex once its frame
// order is mapped onto the local model's (VertexOrder). The binding itself is not sent by the
// server; it is the same because both sides run DeformationModel::Build on the same inputs and
// options, and this check confirms the inputs.
#pragma once

#include "animation/vertex_order.h"
#include "core/model/deformation_model.h"
#include "lib/deform_client.h"

namespace deform::animation {

// FAILED_PRECONDITION naming the first difference; the server's status when GetMeshInfo fails.
grpc::Status CheckServerMatchesReference(client::DeformClient& client,
                                         const deform::v1::MeshSummary& summary,
                                         const DeformationModel& model, const VertexOrder& order);

}  // namespace deform::animation
