// The service's unary calls and the authentication of every call, independent of the transport:
// gRPC's DeformServiceImpl (deform_service.h) and the HTTP endpoints (rpc/web_server.h) both call
// these, so both get the same checks, tenancy and audit lines.
//
// `authorization` is the value of the caller's "authorization" header or metadata ("Bearer
// TOKEN"; empty when absent). Every call authenticates first (UNAUTHENTICATED before anything
// else is looked at, with a token file), checks its strings' lengths (request_limits.h), sees only
// the caller's meshes (MeshRegistry's caller-scoped lookups) and leaves an audit line
// (audit_log.h). Thread-safe; `context` must outlive the call.
#pragma once

#include <string_view>

#include "core/base/status.h"
#include "deform/v1/deform.pb.h"
#include "service/access/identity.h"
#include "service/context/service_context.h"

namespace deform::service {

// The caller behind `authorization`. A caller without a valid token is counted
// (deformd_refused_total{reason="unauthenticated"}) and audited ("-" as its tenant) for `action`
// on `mesh_id` within ServiceContext::CountRefusal's budget of lines; a metrics-role token is
// PERMISSION_DENIED and audited under its tenant.
StatusOr<Identity> AuthenticateCall(ServiceContext& context, std::string_view authorization,
                                    std::string_view action, std::string_view mesh_id);

Status GetMeshInfoCall(ServiceContext& context, std::string_view authorization,
                       const v1::GetMeshInfoRequest& request, v1::GetMeshInfoResponse* response);
Status ListMeshesCall(ServiceContext& context, std::string_view authorization,
                      const v1::ListMeshesRequest& request, v1::ListMeshesResponse* response);
Status UnloadMeshCall(ServiceContext& context, std::string_view authorization,
                      const v1::UnloadMeshRequest& request, v1::UnloadMeshResponse* response);

}  // namespace deform::service
