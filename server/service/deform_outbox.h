// What a Deform stream has to write, in order: notices and frames.
//
//  - Notices (KIND_POSE_REJECTED, KIND_STIFFNESS_APPLIED, KIND_STIFFNESS_REJECTED) are written in
//    the order they were added and never dropped, except droppable ones (rejected poses) while
//    kMaxNoticeBacklog notices wait unwritten: a client flooding bad poses without reading must not
//    grow the server's memory.
//  - Frames go through FrameSlots (at most one ready, the latest wins). A frame is written after
//    every notice added before it was published and before every notice added after, so the
//    KIND_STIFFNESS_APPLIED notice separates the frames of two stiffness versions.
//
// It is the Deform stream's write queue for StreamWritePump: TakeNextWrite() hands out the next
// message, which stays untouched until the next TakeNextWrite().
//
// Thread safety: none; the stream's lock guards every call (the working frame's contents belong to
// the solve, see FrameSlots).
#pragma once

#include <cstddef>
#include <cstdint>
#include <deque>
#include <string>

#include "deform/v1/deform.pb.h"
#include "service/frame_slots.h"

namespace deform::service {

class DeformOutbox {
 public:
  // Unwritten notices beyond which droppable notices are dropped.
  static constexpr std::size_t kMaxNoticeBacklog = 1024;

  // Sizes the frames (FrameSlots::Allocate).
  void AllocateFrames(int num_vertices, std::size_t encoded_bytes = 0, int transform_floats = 0) {
    frames_.Allocate(num_vertices, encoded_bytes, transform_floats);
  }
  // The frame the next solve fills (FrameSlots::working).
  v1::DeformResponse* working_frame() { return frames_.working(); }
  // The working frame is finished; it goes after the notices added so far.
  void PublishFrame();

  void AddNotice(v1::Notice::Kind kind, std::uint64_t sequence, std::uint64_t stiffness_version,
                 const std::string& message, double factor_ms = 0);
  // Whether a droppable notice would be dropped now (check before building its message).
  bool notice_backlog_full() const { return notices_.size() >= kMaxNoticeBacklog; }

  // The next message to write (the frame when no notice must go before it), or nullptr.
  const v1::DeformResponse* TakeNextWrite();
  // Whether the message last taken is a frame.
  bool frame_in_flight() const { return frame_in_flight_; }

  // Nothing waits to be written (the message in flight aside).
  bool empty() const { return !frames_.has_ready() && notices_.empty(); }

 private:
  FrameSlots frames_;
  std::deque<v1::DeformResponse> notices_;
  std::size_t notices_before_frame_ = 0;  // of notices_, those to write before the ready frame
  v1::DeformResponse notice_in_flight_;
  bool frame_in_flight_ = false;
};

}  // namespace deform::service
