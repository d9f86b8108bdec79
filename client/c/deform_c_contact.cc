// The C API's contact queries (deform_c.h): a handle over the C++ library's ContactQuery.
#include <cstring>
#include <memory>
#include <string>

#include "c_api_errors.h"
#include "c_api_handles.h"
#include "deform_c.h"

struct deform_contact {
  std::shared_ptr<deform::client::DeformClient> client;
  std::unique_ptr<deform::client::ContactQuery> query;
};

using deform::c_api::Fail;
using deform::c_api::FromGrpc;
using deform::c_api::Get;
using deform::c_api::Guarded;
using deform::c_api::Succeed;

namespace {

void CopyVector(const deform::v1::Vector3& v, double out[3]) {
  out[0] = v.x();
  out[1] = v.y();
  out[2] = v.z();
}

}  // namespace

extern "C" {

deform_status deform_contact_open(deform_client* client, const char* mesh_id,
                                  uint64_t deform_stream_id, double stiffness,
                                  deform_contact** out) {
  return Guarded(__func__, {{client, "client"}, {mesh_id, "mesh_id"}, {out, "out"}}, [&] {
    deform::v1::ContactQueryStart start;
    start.set_mesh_id(mesh_id);
    start.set_deform_stream_id(deform_stream_id);
    start.set_stiffness(stiffness);
    auto handle = std::make_unique<deform_contact>();
    handle->client = client->client;
    const grpc::Status opened = client->client->OpenContactQuery(start, &handle->query);
    if (!opened.ok()) return FromGrpc(opened, "deform_contact_open");
    *out = handle.release();
    return Succeed();
  });
}

deform_status deform_contact_query(deform_contact* contact, const deform_tool* tool,
                                   deform_contact_result* result) {
  return Guarded(__func__, {{contact, "contact"}, {tool, "tool"}, {result, "result"}}, [&] {
    deform::v1::ToolState state;
    switch (tool->shape) {
      case DEFORM_TOOL_SPHERE:
        state.set_shape(deform::v1::ToolState::SHAPE_SPHERE);
        break;
      case DEFORM_TOOL_CAPSULE:
        state.set_shape(deform::v1::ToolState::SHAPE_CAPSULE);
        state.mutable_end()->set_x(tool->end[0]);
        state.mutable_end()->set_y(tool->end[1]);
        state.mutable_end()->set_z(tool->end[2]);
        break;
      default:
        return Fail(DEFORM_INVALID_ARGUMENT, "deform_contact_query: unknown tool shape " +
                                                 std::to_string(tool->shape) +
                                                 " (1 sphere, 2 capsule)");
    }
    state.mutable_center()->set_x(tool->center[0]);
    state.mutable_center()->set_y(tool->center[1]);
    state.mutable_center()->set_z(tool->center[2]);
    state.set_radius(tool->radius);
    deform::v1::ContactResult answer;
    const grpc::Status queried = contact->query->Query(state, &answer);
    if (!queried.ok()) return FromGrpc(queried, "deform_contact_query");
    result->sequence = answer.sequence();
    CopyVector(answer.point(), result->point);
    CopyVector(answer.normal(), result->normal);
    result->depth = answer.depth();
    CopyVector(answer.force(), result->force);
    result->signed_distance = answer.signed_distance();
    result->material_weight = answer.material_weight();
    result->frame_number = answer.frame_number();
    result->frame_sequence = answer.frame_sequence();
    return Succeed();
  });
}

deform_status deform_contact_diagonal(const deform_contact* contact, double* diagonal) {
  return Get(__func__, contact, "contact", diagonal, "diagonal",
             [](const deform_contact& c) { return c.query->started().bounding_box_diagonal(); });
}

deform_status deform_contact_close(deform_contact* contact) {
  if (contact == nullptr) return Succeed();
  return Guarded(__func__, [&] {
    std::unique_ptr<deform_contact> owned(contact);
    const grpc::Status closed = owned->query->Close();
    if (!closed.ok()) return FromGrpc(closed, "deform_contact_close");
    return Succeed();
  });
}

}  // extern "C"
