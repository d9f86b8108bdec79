#include "service/deform/frame_slots.h"

#include <cassert>
#include <cstddef>
#include <utility>

namespace deform::service {

FrameSlots::FrameSlots() : working_(&frames_[0]), ready_(&frames_[1]), writing_(&frames_[2]) {}

void FrameSlots::Allocate(int num_vertices, std::size_t encoded_bytes, int transform_floats,
                          std::size_t bone_surface_bytes, bool constraints) {
  const std::size_t position_bytes = static_cast<std::size_t>(num_vertices) * 12;
  for (v1::DeformResponse& response : frames_) {
    v1::DeformFrame* frame = response.mutable_frame();
    if (encoded_bytes > 0) {
      v1::EncodedPositions* encoded = frame->mutable_encoded();
      encoded->mutable_data()->reserve(encoded_bytes);
      encoded->mutable_origin()->Reserve(3);
      encoded->mutable_bone_transforms()->Reserve(transform_floats);
    } else {
      frame->mutable_positions()->resize(position_bytes);
    }
    frame->mutable_timings();
    if (bone_surface_bytes > 0) frame->mutable_bone_transforms()->resize(bone_surface_bytes);
    if (constraints) frame->mutable_constraints();
  }
}

void FrameSlots::Publish() {
  if (has_ready_) {
    // The unwritten frame is superseded: its pose and the poses it skipped count as skipped.
    v1::DeformFrame* frame = working_->mutable_frame();
    frame->set_skipped_poses(frame->skipped_poses() + ready_->frame().skipped_poses() + 1);
  }
  std::swap(working_, ready_);
  has_ready_ = true;
}

const v1::DeformResponse* FrameSlots::StartWriting() {
  assert(has_ready_ && "StartWriting without a ready frame");
  std::swap(ready_, writing_);
  has_ready_ = false;
  return writing_;
}

}  // namespace deform::service
