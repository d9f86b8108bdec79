// The Deform RPC: one stream handler per call, whatever the transport (gRPC, or a WebSocket:
// stream_transport.h), owned by shared_ptrs (the transport's until OnDone, and each posted worker
// task's; self_owning_handler.h): freed when the last of them is done with it. Both transports run
// this same code: validation, limits (--max-streams, per tenant), the worker pool, the outbox and
// its backpressure, and the per-stream counts of the closing log line (frames written, poses
// rejected, notices dropped: where per-stream metrics are fed, for every transport at once).
//
// Per stream: a shared_ptr to the mesh entry (keeps the model alive after UnloadMesh; frames then
// carry mesh_unloaded), its own solve buffers and frame messages, its current factorization and
// stiffness version. The state is split into parts, each with its own contract and tests:
//  - PendingPoseSlot (pending_pose_slot.h): the latest pose wins, skipped poses, the solve task;
//  - StiffnessSwitch (stiffness_switch.h): the factorization in use and the refactorizations;
//  - DeformOutbox (deform_outbox.h) over FrameSlots (frame_slots.h): notices and frames, in order;
//  - StreamWritePump (stream_write_pump.h): one write in flight, the finish;
//  - FrameSolver (frame_solver.h): the solve into a frame, on the stream's own buffers.
//
// Threads and ordering:
//  - gRPC threads run the reactions. OnReadDone only converts the request: a pose is resolved
//    against the skeleton and put into the stream's single pending-pose slot (a newer pose
//    replaces one not yet solved: latest wins, counted in skipped_poses); a stiffness update is
//    checked and its refactorization posted to the worker pool in the background.
//  - The stream is then queued (at most once) on the worker pool's urgent queue. A worker takes
//    the pending pose (together with the pending poses of other queued streams on the same mesh
//    and factorization, up to --batch-frames, which it solves in one pass over the factor: each
//    stream's frame is the one it would get alone, and no stream waits for others to queue),
//    solves it without holding any lock, encodes float32 positions into the
//    stream's own frame message and starts the write itself. At most one write is in flight; a
//    frame finished while one is in flight waits in a one-frame slot where a newer frame replaces
//    it (its pose then counts as skipped in the next frame, so that skipped_poses is the number
//    of poses since the previous frame that got no frame of their own).
//  - A refactorization runs in the background while frames keep using the old factorization. It
//    is switched in between two solves, together with the KIND_STIFFNESS_APPLIED notice, so every
//    frame written after that notice carries the new version and every frame before it the old.
//    One refactorization runs per stream; a newer update waiting behind it replaces an older one
//    (the older gets KIND_STIFFNESS_REJECTED, "superseded").
//  - Notices are written in order and never dropped (except KIND_POSE_REJECTED beyond a backlog of
//    1,024 unwritten notices).
//  - The parts are guarded by the reactor's mutex (annotated, thread_annotations.h); the solver
//    and the pose being solved belong to the solve task, the request buffers to the reader.
//
// `start` finds the mesh as the caller may see it (another tenant's mesh is NOT_FOUND) and counts
// the stream against the caller's tenant's stream limit (RESOURCE_EXHAUSTED beyond it).
//
// The stream ends with OK after the client half-closes and everything pending is written, with
// INVALID_ARGUMENT / NOT_FOUND for a bad or unknown `start`, CANCELLED when the client cancels,
// UNAVAILABLE when the server drains.
#pragma once

#include "deform/v1/deform.pb.h"
#include "service/access/identity.h"
#include "service/context/service_context.h"
#include "service/transport/stream_transport.h"

namespace deform::service {

using DeformTransport = StreamTransport<v1::DeformRequest, v1::DeformResponse>;

// A new handler for one Deform call over `transport`; it starts reading at once. `context` and the
// transport must outlive it (the transport until its OnDone()).
StreamHandler* NewDeformStream(ServiceContext* context, Identity caller,
                               DeformTransport* transport);

}  // namespace deform::service
