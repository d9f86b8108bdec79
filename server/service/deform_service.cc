#include "service/deform_service.h"

#include <spdlog/spdlog.h>

#include "service/deform_stream_reactor.h"
#include "service/load_mesh_reactor.h"
#include "service/proto_conversion.h"
#include "service/request_limits.h"
#include "service/status_mapping.h"

namespace deform::service {

grpc::ServerBidiReactor<v1::LoadMeshRequest, v1::LoadMeshResponse>* DeformServiceImpl::LoadMesh(
    grpc::CallbackServerContext* /*context*/) {
  return NewLoadMeshReactor(core_);
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
  auto entry = core_->registry.Find(request->mesh_id());
  if (!entry.ok()) {
    reactor->Finish(ToGrpcStatus(entry.status()));
    return reactor;
  }
  FillMeshSummary(**entry, response->mutable_summary());
  if (request->include_geometry()) FillMeshGeometry(**entry, response);
  reactor->Finish(grpc::Status::OK);
  return reactor;
}

grpc::ServerUnaryReactor* DeformServiceImpl::ListMeshes(grpc::CallbackServerContext* context,
                                                        const v1::ListMeshesRequest* /*request*/,
                                                        v1::ListMeshesResponse* response) {
  for (const auto& entry : core_->registry.List()) FillMeshSummary(*entry, response->add_meshes());
  grpc::ServerUnaryReactor* reactor = context->DefaultReactor();
  reactor->Finish(grpc::Status::OK);
  return reactor;
}

grpc::ServerUnaryReactor* DeformServiceImpl::UnloadMesh(grpc::CallbackServerContext* context,
                                                        const v1::UnloadMeshRequest* request,
                                                        v1::UnloadMeshResponse* /*response*/) {
  Status status = CheckLength(request->mesh_id(), kMaxMeshIdBytes, "mesh_id");
  if (status.ok()) status = core_->registry.Unload(request->mesh_id());
  if (status.ok()) spdlog::info("mesh={} unloaded", request->mesh_id());
  grpc::ServerUnaryReactor* reactor = context->DefaultReactor();
  reactor->Finish(ToGrpcStatus(status));
  return reactor;
}

grpc::ServerBidiReactor<v1::DeformRequest, v1::DeformResponse>* DeformServiceImpl::Deform(
    grpc::CallbackServerContext* /*context*/) {
  return NewDeformStreamReactor(core_);
}

}  // namespace deform::service
