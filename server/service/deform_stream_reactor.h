// The Deform RPC: one reactor per stream, owned by shared_ptrs (gRPC's until OnDone, and each
// posted worker task's; shared_reactor.h): freed when the last of them is done with it.
//
// Per stream: a shared_ptr to the mesh entry (keeps the model alive after UnloadMesh; frames then
// carry mesh_unloaded), its own DeformScratch and frame buffers, its current factorisation and
// stiffness version.
//
// Threads and ordering:
//  - gRPC threads run the reactions. OnReadDone only converts the request: a pose is resolved
//    against the skeleton and put into the stream's single pending-pose slot (a newer pose
//    replaces one not yet solved: latest wins, counted in skipped_poses); a stiffness update is
//    checked and its refactorisation posted to the worker pool in the background.
//  - The stream is then queued (at most once) on the worker pool's urgent queue. A worker takes
//    the pending pose, solves it without holding any lock, encodes float32 positions into the
//    stream's own frame message and starts the write itself. At most one write is in flight; a
//    frame finished while one is in flight waits in a one-frame slot where a newer frame replaces
//    it (its pose then counts as skipped in the next frame, so that skipped_poses is the number
//    of poses since the previous frame that got no frame of their own).
//  - A refactorisation runs in the background while frames keep using the old factorisation. It
//    is switched in between two solves, together with the KIND_STIFFNESS_APPLIED notice, so every
//    frame written after that notice carries the new version and every frame before it the old.
//    One refactorisation runs per stream; a newer update waiting behind it replaces an older one
//    (the older gets KIND_STIFFNESS_REJECTED, "superseded").
//  - Notices are written in order and never dropped (except KIND_POSE_REJECTED beyond a backlog of
//    1,024 unwritten notices).
//
// The stream ends with OK after the client half-closes and everything pending is written, with
// INVALID_ARGUMENT / NOT_FOUND for a bad or unknown `start`, CANCELLED when the client cancels,
// UNAVAILABLE when the server drains.
#pragma once

#include <grpcpp/support/server_callback.h>

#include "deform/v1/deform.pb.h"
#include "service/service_core.h"

namespace deform::service {

// A new reactor for one Deform call. `core` must outlive it.
grpc::ServerBidiReactor<v1::DeformRequest, v1::DeformResponse>* NewDeformStreamReactor(
    ServiceCore* core);

}  // namespace deform::service
