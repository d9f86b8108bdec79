#include "service/rpc/unary_calls.h"

#include <string>

#include "service/access/audit_log.h"
#include "service/base/log_budget.h"
#include "service/base/request_limits.h"
#include "service/messages/frame_encoding.h"
#include "service/messages/proto_conversion.h"

namespace deform::service {
namespace {

std::string ResultText(const Status& status) { return status.ok() ? "OK" : status.ToString(); }

// A mesh id as an audit line names it before its length was checked: cut to the limit.
std::string_view BoundedForAudit(std::string_view mesh_id) {
  return mesh_id.substr(0, kMaxMeshIdBytes);
}

}  // namespace

StatusOr<Identity> AuthenticateCall(ServiceContext& context, std::string_view authorization,
                                    std::string_view action, std::string_view mesh_id) {
  StatusOr<Identity> caller = context.auth().Authenticate(authorization);
  if (!caller.ok()) {
    // Anyone can send a bad token: counted always, audited within the refusal lines' budget.
    std::uint64_t held_back = 0;
    if (context.CountRefusal(ServiceMetrics::Refusal::kUnauthenticated, &held_back)) {
      Audit("-", action, mesh_id, caller.status().ToString() + HeldBackNote(held_back));
    }
    return caller;
  }
  if (caller->role == Role::kMetrics) {
    const Status refused =
        Status::PermissionDenied("this token has the metrics role: it may only scrape /metrics");
    Audit(caller->tenant, action, mesh_id, refused.ToString());
    return refused;
  }
  return caller;
}

Status GetMeshInfoCall(ServiceContext& context, std::string_view authorization,
                       const v1::GetMeshInfoRequest& request, v1::GetMeshInfoResponse* response) {
  const char* action = request.include_geometry() ? "download" : "get_mesh_info";
  // Authentication first: an unauthenticated caller learns nothing of the request's checks.
  DEFORM_ASSIGN_OR_RETURN(Identity caller, AuthenticateCall(context, authorization, action,
                                                            BoundedForAudit(request.mesh_id())));
  DEFORM_RETURN_IF_ERROR(CheckLength(request.mesh_id(), kMaxMeshIdBytes, "mesh_id"));
  auto entry = context.FindMesh(request.mesh_id(), caller);
  Audit(caller.tenant, action, request.mesh_id(), ResultText(entry.status()));
  if (!entry.ok()) return entry.status();
  FillMeshSummary(**entry, response->mutable_summary());
  if (request.include_geometry()) FillMeshGeometry(**entry, response);
  if (request.include_prediction_weights()) {
    FillPredictionWeights(**entry, response->mutable_prediction_weights());
  }
  return Status::Ok();
}

Status ListMeshesCall(ServiceContext& context, std::string_view authorization,
                      const v1::ListMeshesRequest& /*request*/, v1::ListMeshesResponse* response) {
  DEFORM_ASSIGN_OR_RETURN(Identity caller, AuthenticateCall(context, authorization, "list", ""));
  const auto meshes = context.registry().List(caller);
  for (const auto& entry : meshes) FillMeshSummary(*entry, response->add_meshes());
  Audit(caller.tenant, "list", "", "OK: " + std::to_string(meshes.size()) + " meshes");
  return Status::Ok();
}

Status UnloadMeshCall(ServiceContext& context, std::string_view authorization,
                      const v1::UnloadMeshRequest& request, v1::UnloadMeshResponse* /*response*/) {
  DEFORM_ASSIGN_OR_RETURN(Identity caller, AuthenticateCall(context, authorization, "unload",
                                                            BoundedForAudit(request.mesh_id())));
  DEFORM_RETURN_IF_ERROR(CheckLength(request.mesh_id(), kMaxMeshIdBytes, "mesh_id"));
  // The stored entry first: a mesh whose entry cannot be deleted stays loaded (else it would
  // come back at the next start), and the caller is told.
  MeshStore* const store = context.store();
  Status status = context.registry().Find(request.mesh_id(), caller).status();
  if (status.ok() && store != nullptr) status = store->Remove(request.mesh_id());
  if (status.ok()) {
    status = context.registry().Unload(request.mesh_id(), caller);
  } else if (status.code() == StatusCode::kNotFound && store != nullptr && store->shared()) {
    // Loaded by another replica only: its entry goes, and that replica unloads it when a call
    // next names it (ServiceContext::FindMesh).
    const StatusOr<std::string> owner = store->PeekTenant(request.mesh_id());
    if (owner.ok() && caller.CanAccess(*owner)) status = store->Remove(request.mesh_id());
  }
  Audit(caller.tenant, "unload", request.mesh_id(), ResultText(status));
  return status;
}

}  // namespace deform::service
