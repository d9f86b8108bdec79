#include "service/deform_service.h"

#include <spdlog/spdlog.h>

#include "service/audit_log.h"
#include "service/deform_stream_reactor.h"
#include "service/frame_encoding.h"
#include "service/load_mesh_reactor.h"
#include "service/proto_conversion.h"
#include "service/rejected_call.h"
#include "service/request_limits.h"
#include "service/status_mapping.h"

namespace deform::service {
namespace {

// The value of the call's "authorization" metadata, or empty.
std::string_view AuthorizationOf(const grpc::CallbackServerContext* context) {
  const auto& metadata = context->client_metadata();
  const auto it = metadata.find("authorization");
  if (it == metadata.end()) return {};
  return std::string_view(it->second.data(), it->second.size());
}

// The caller of `context`; an unauthenticated call is audited ("-" as its tenant) here.
StatusOr<Identity> Caller(const ServiceCore& core, const grpc::CallbackServerContext* context,
                          std::string_view action, std::string_view mesh_id) {
  StatusOr<Identity> caller = core.auth.Authenticate(AuthorizationOf(context));
  if (!caller.ok()) Audit("-", action, mesh_id, caller.status().ToString());
  return caller;
}

std::string ResultText(const Status& status) { return status.ok() ? "OK" : status.ToString(); }

}  // namespace

grpc::ServerBidiReactor<v1::LoadMeshRequest, v1::LoadMeshResponse>* DeformServiceImpl::LoadMesh(
    grpc::CallbackServerContext* context) {
  StatusOr<Identity> caller = Caller(*core_, context, "load", "");
  if (!caller.ok()) {
    return new RejectedBidiCall<v1::LoadMeshRequest, v1::LoadMeshResponse>(
        ToGrpcStatus(caller.status()));
  }
  return NewLoadMeshReactor(core_, std::move(*caller));
}

grpc::ServerUnaryReactor* DeformServiceImpl::GetMeshInfo(grpc::CallbackServerContext* context,
                                                         const v1::GetMeshInfoRequest* request,
                                                         v1::GetMeshInfoResponse* response) {
  grpc::ServerUnaryReactor* reactor = context->DefaultReactor();
  const Status id_length = CheckLength(request->mesh_id(), kMaxMeshIdBytes, "mesh_id");
  if (!id_length.ok()) {
    reactor->Finish(ToGrpcStatus(id_length));
    return reactor;
  }
  const char* action = request->include_geometry() ? "download" : "get_mesh_info";
  StatusOr<Identity> caller = Caller(*core_, context, action, request->mesh_id());
  if (!caller.ok()) {
    reactor->Finish(ToGrpcStatus(caller.status()));
    return reactor;
  }
  auto entry = core_->registry.Find(request->mesh_id(), *caller);
  Audit(caller->tenant, action, request->mesh_id(), ResultText(entry.status()));
  if (!entry.ok()) {
    reactor->Finish(ToGrpcStatus(entry.status()));
    return reactor;
  }
  FillMeshSummary(**entry, response->mutable_summary());
  if (request->include_geometry()) FillMeshGeometry(**entry, response);
  if (request->include_prediction_weights()) {
    FillPredictionWeights(**entry, response->mutable_prediction_weights());
  }
  reactor->Finish(grpc::Status::OK);
  return reactor;
}

grpc::ServerUnaryReactor* DeformServiceImpl::ListMeshes(grpc::CallbackServerContext* context,
                                                        const v1::ListMeshesRequest* /*request*/,
                                                        v1::ListMeshesResponse* response) {
  grpc::ServerUnaryReactor* reactor = context->DefaultReactor();
  StatusOr<Identity> caller = Caller(*core_, context, "list", "");
  if (!caller.ok()) {
    reactor->Finish(ToGrpcStatus(caller.status()));
    return reactor;
  }
  const auto meshes = core_->registry.List(*caller);
  for (const auto& entry : meshes) FillMeshSummary(*entry, response->add_meshes());
  Audit(caller->tenant, "list", "", "OK: " + std::to_string(meshes.size()) + " meshes");
  reactor->Finish(grpc::Status::OK);
  return reactor;
}

grpc::ServerUnaryReactor* DeformServiceImpl::UnloadMesh(grpc::CallbackServerContext* context,
                                                        const v1::UnloadMeshRequest* request,
                                                        v1::UnloadMeshResponse* /*response*/) {
  grpc::ServerUnaryReactor* reactor = context->DefaultReactor();
  const Status id_length = CheckLength(request->mesh_id(), kMaxMeshIdBytes, "mesh_id");
  if (!id_length.ok()) {
    reactor->Finish(ToGrpcStatus(id_length));
    return reactor;
  }
  StatusOr<Identity> caller = Caller(*core_, context, "unload", request->mesh_id());
  if (!caller.ok()) {
    reactor->Finish(ToGrpcStatus(caller.status()));
    return reactor;
  }
  const Status status = core_->registry.Unload(request->mesh_id(), *caller);
  if (status.ok() && core_->store != nullptr) core_->store->Remove(request->mesh_id());
  Audit(caller->tenant, "unload", request->mesh_id(), ResultText(status));
  reactor->Finish(ToGrpcStatus(status));
  return reactor;
}

grpc::ServerBidiReactor<v1::DeformRequest, v1::DeformResponse>* DeformServiceImpl::Deform(
    grpc::CallbackServerContext* context) {
  StatusOr<Identity> caller = Caller(*core_, context, "deform", "");
  if (!caller.ok()) {
    return new RejectedBidiCall<v1::DeformRequest, v1::DeformResponse>(
        ToGrpcStatus(caller.status()));
  }
  return NewDeformStreamReactor(core_, std::move(*caller));
}

}  // namespace deform::service
