// The LoadMesh RPC: one reactor per call, owned by shared_ptrs (gRPC's until OnDone, and the
// build task's; shared_reactor.h): freed when both are done with it.
//
// Reads the header, then the upload's chunks into memory (checking the announced size and the
// upload limit as they come), then on half-close sends RECEIVED and hands parsing, validation and
// precomputation to the worker pool (background priority). Progress messages (VALIDATED, WEIGHTS,
// FACTORISED, READY) are written in order, one write in flight at a time (stream_write_pump.h,
// FinishRule::kFirstRequestWins); the call ends with OK after READY, or with the mapped error
// status (INVALID_ARGUMENT naming the problem, RESOURCE_EXHAUSTED for limits). A mesh slot is
// reserved when the header arrives, so a client over the mesh limit is refused before it sends its
// bytes.
//
// The mesh belongs to the caller's tenant (its slot and memory count against the tenant's
// limits too). With a store (ServiceCore::store), the header and the upload's bytes are written to
// it before parsing and kept once the mesh is registered (mesh_store.h); an audit line records
// the outcome.
//
// Threads: gRPC's threads run the reactions and own the upload's buffers until the build is
// posted; then the build task (a worker) owns them. The outbox and the pump are guarded by the
// reactor's mutex.
#pragma once

#include <grpcpp/support/server_callback.h>

#include "deform/v1/deform.pb.h"
#include "service/identity.h"
#include "service/service_core.h"

namespace deform::service {

// A new reactor for one LoadMesh call. `core` must outlive it.
grpc::ServerBidiReactor<v1::LoadMeshRequest, v1::LoadMeshResponse>* NewLoadMeshReactor(
    ServiceCore* core, Identity caller);

}  // namespace deform::service
