// The three frame messages of one Deform stream, sized once and rotated by pointer, so that a
// frame costs no allocation:
//  - working: the frame a solve fills (the solve owns its contents, without the lock, from when it
//    reads working() until it calls Publish());
//  - ready:   the newest finished frame not yet written; at most one, the latest wins;
//  - writing: the frame the transport is writing, untouched until StartWriting() is called again
//    (which the one-write-in-flight rule allows only after that write has completed).
// A ready frame superseded by a newer one is never written; the newer frame's skipped_poses then
// grows by the superseded frame's skipped_poses + 1, so that skipped_poses always counts the poses
// since the previous written frame that got no frame of their own.
//
// Thread safety: none; the stream's lock guards every call.
#pragma once

#include <array>

#include "deform/v1/deform.pb.h"

namespace deform::service {

class FrameSlots {
 public:
  FrameSlots();
  FrameSlots(const FrameSlots&) = delete;
  FrameSlots& operator=(const FrameSlots&) = delete;

  // Sizes every frame for `num_vertices` (12 bytes of positions per vertex), or with
  // `encoded_bytes` > 0 its encoded positions for that many bytes and `transform_floats` bone
  // transform floats, its bone surfaces' transforms for `bone_surface_bytes`, and creates its
  // timings and, with `constraints`, its constraint report: the only allocation.
  void Allocate(int num_vertices, std::size_t encoded_bytes = 0, int transform_floats = 0,
                std::size_t bone_surface_bytes = 0, bool constraints = false);

  // The frame the next solve fills. Its pointer changes only in Publish().
  v1::DeformResponse* working() { return working_; }
  // The working frame is finished: it becomes the ready frame (superseding an unwritten one).
  void Publish();

  bool has_ready() const { return has_ready_; }
  // The ready frame becomes the writing frame, returned for the transport. Precondition:
  // has_ready() and the previous writing frame's write has completed.
  const v1::DeformResponse* StartWriting();

 private:
  std::array<v1::DeformResponse, 3> frames_;
  v1::DeformResponse* working_;
  v1::DeformResponse* ready_;
  v1::DeformResponse* writing_;
  bool has_ready_ = false;
};

}  // namespace deform::service
