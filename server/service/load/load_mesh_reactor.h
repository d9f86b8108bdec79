// The LoadMesh RPC: one stream handler per call, whatever the transport (gRPC, or a WebSocket:
// stream_transport.h), owned by shared_ptrs (the transport's until OnDone, and the build task's;
// self_owning_handler.h): freed when both are done with it.
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
// limits too). With a store (ServiceContext::store), the header and the upload's bytes are written
// to it before parsing and kept once the mesh is registered (mesh_store.h); an audit line records
// the outcome.
//
// Threads: gRPC's threads run the reactions and own the upload's buffers until the build is
// posted; then the build task (a worker) owns them. The outbox and the pump are guarded by the
// reactor's mutex.
#pragma once

#include "deform/v1/deform.pb.h"
#include "service/access/identity.h"
#include "service/context/service_context.h"
#include "service/transport/stream_transport.h"

namespace deform::service {

using LoadMeshTransport = StreamTransport<v1::LoadMeshRequest, v1::LoadMeshResponse>;

// A new handler for one LoadMesh call over `transport`; it starts reading at once. `context` and
// the transport must outlive it (the transport until its OnDone()).
StreamHandler* NewLoadMeshStream(ServiceContext* context, Identity caller,
                                 LoadMeshTransport* transport);

}  // namespace deform::service
