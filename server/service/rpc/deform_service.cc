#include "service/rpc/deform_service.h"

#include <string_view>

#include "service/contact/contact_query_reactor.h"
#include "service/deform/deform_stream_reactor.h"
#include "service/load/load_mesh_reactor.h"
#include "service/rpc/unary_calls.h"
#include "service/transport/grpc_stream_adapter.h"
#include "service/transport/rejected_call.h"
#include "service/transport/status_mapping.h"

namespace deform::service {
namespace {

// The value of the call's "authorization" metadata, or empty.
std::string_view AuthorizationOf(const grpc::CallbackServerContext* context) {
  const auto& metadata = context->client_metadata();
  const auto it = metadata.find("authorization");
  if (it == metadata.end()) return {};
  return std::string_view(it->second.data(), it->second.size());
}

grpc::ServerUnaryReactor* FinishUnary(grpc::CallbackServerContext* context, const Status& status) {
  grpc::ServerUnaryReactor* reactor = context->DefaultReactor();
  reactor->Finish(ToGrpcStatus(status));
  return reactor;
}

}  // namespace

grpc::ServerBidiReactor<v1::LoadMeshRequest, v1::LoadMeshResponse>* DeformServiceImpl::LoadMesh(
    grpc::CallbackServerContext* context) {
  StatusOr<Identity> caller = AuthenticateCall(*context_, AuthorizationOf(context), "load", "");
  if (!caller.ok()) {
    return new RejectedBidiCall<v1::LoadMeshRequest, v1::LoadMeshResponse>(
        ToGrpcStatus(caller.status()));
  }
  return GrpcStreamAdapter<v1::LoadMeshRequest, v1::LoadMeshResponse>::Create(
      [&](LoadMeshTransport* transport) {
        return NewLoadMeshStream(context_, std::move(*caller), transport);
      });
}

grpc::ServerUnaryReactor* DeformServiceImpl::GetMeshInfo(grpc::CallbackServerContext* context,
                                                         const v1::GetMeshInfoRequest* request,
                                                         v1::GetMeshInfoResponse* response) {
  return FinishUnary(context,
                     GetMeshInfoCall(*context_, AuthorizationOf(context), *request, response));
}

grpc::ServerUnaryReactor* DeformServiceImpl::ListMeshes(grpc::CallbackServerContext* context,
                                                        const v1::ListMeshesRequest* request,
                                                        v1::ListMeshesResponse* response) {
  return FinishUnary(context,
                     ListMeshesCall(*context_, AuthorizationOf(context), *request, response));
}

grpc::ServerUnaryReactor* DeformServiceImpl::UnloadMesh(grpc::CallbackServerContext* context,
                                                        const v1::UnloadMeshRequest* request,
                                                        v1::UnloadMeshResponse* response) {
  return FinishUnary(context,
                     UnloadMeshCall(*context_, AuthorizationOf(context), *request, response));
}

grpc::ServerBidiReactor<v1::DeformRequest, v1::DeformResponse>* DeformServiceImpl::Deform(
    grpc::CallbackServerContext* context) {
  StatusOr<Identity> caller = AuthenticateCall(*context_, AuthorizationOf(context), "deform", "");
  if (!caller.ok()) {
    return new RejectedBidiCall<v1::DeformRequest, v1::DeformResponse>(
        ToGrpcStatus(caller.status()));
  }
  return GrpcStreamAdapter<v1::DeformRequest, v1::DeformResponse>::Create(
      [&](DeformTransport* transport) {
        return NewDeformStream(context_, std::move(*caller), transport);
      });
}

grpc::ServerBidiReactor<v1::QueryContactRequest, v1::QueryContactResponse>*
DeformServiceImpl::QueryContact(grpc::CallbackServerContext* context) {
  StatusOr<Identity> caller = AuthenticateCall(*context_, AuthorizationOf(context), "contact", "");
  if (!caller.ok()) {
    return new RejectedBidiCall<v1::QueryContactRequest, v1::QueryContactResponse>(
        ToGrpcStatus(caller.status()));
  }
  return GrpcStreamAdapter<v1::QueryContactRequest, v1::QueryContactResponse>::Create(
      [&](ContactQueryTransport* transport) {
        return NewContactQueryStream(context_, std::move(*caller), transport);
      });
}

}  // namespace deform::service
