// The deform.v1.DeformService implementation: a thin layer that converts messages, looks things
// up in the ServiceContext and maps statuses. Streaming RPCs get their own reactors
// (load_mesh_reactor.h, deform_stream_reactor.h, contact_query_reactor.h). Thread-safe; `context`
// must outlive it.
//
// Every call is authenticated first (context->auth(), from the "authorization" metadata): without a
// valid token it ends with UNAUTHENTICATED before anything else is looked at. Then the caller's
// identity scopes what it sees (MeshRegistry's caller-scoped lookups), and each call leaves an
// audit line (audit_log.h).
#pragma once

#include "deform/v1/deform.grpc.pb.h"
#include "service/context/service_context.h"

namespace deform::service {

class DeformServiceImpl final : public v1::DeformService::CallbackService {
 public:
  explicit DeformServiceImpl(ServiceContext* context) : context_(context) {}

  grpc::ServerBidiReactor<v1::LoadMeshRequest, v1::LoadMeshResponse>* LoadMesh(
      grpc::CallbackServerContext* context) override;
  grpc::ServerUnaryReactor* GetMeshInfo(grpc::CallbackServerContext* context,
                                        const v1::GetMeshInfoRequest* request,
                                        v1::GetMeshInfoResponse* response) override;
  grpc::ServerUnaryReactor* ListMeshes(grpc::CallbackServerContext* context,
                                       const v1::ListMeshesRequest* request,
                                       v1::ListMeshesResponse* response) override;
  grpc::ServerUnaryReactor* UnloadMesh(grpc::CallbackServerContext* context,
                                       const v1::UnloadMeshRequest* request,
                                       v1::UnloadMeshResponse* response) override;
  grpc::ServerBidiReactor<v1::DeformRequest, v1::DeformResponse>* Deform(
      grpc::CallbackServerContext* context) override;
  grpc::ServerBidiReactor<v1::QueryContactRequest, v1::QueryContactResponse>* QueryContact(
      grpc::CallbackServerContext* context) override;

 private:
  ServiceContext* const context_;
};

}  // namespace deform::service
