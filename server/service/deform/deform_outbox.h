// What a Deform stream has to write, in order: notices and frames.
//
//  - Notices (KIND_POSE_REJECTED, KIND_STIFFNESS_APPLIED, KIND_STIFFNESS_REJECTED) are written in
//    the order they were added. The backlog of unwritten notices is bounded in count and in bytes
//    (kMaxNoticeBacklog, kMaxNoticeBacklogBytes; each message is cut to kMaxNoticeMessageBytes): a
//    client that sends without reading must not grow the server's memory. While it is full,
//    rejections (poses and stiffness updates alike) are dropped and counted; applied-stiffness
//    notices are never dropped (they separate two stiffness versions' frames), so the stream stops
//    reading requests while the backlog is full (notice_backlog_full(), the reactor's job), which
//    bounds them too.
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

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <deque>
#include <string>

#include "deform/v1/deform.pb.h"
#include "service/deform/frame_slots.h"

namespace deform::service {

class DeformOutbox {
 public:
  // Unwritten notices, and their serialized bytes, beyond which rejections are dropped.
  static constexpr std::size_t kMaxNoticeBacklog = 1024;
  static constexpr std::size_t kMaxNoticeBacklogBytes = std::size_t{256} << 10;
  // A notice's message is cut to this many bytes.
  static constexpr std::size_t kMaxNoticeMessageBytes = 1024;

  DeformOutbox() = default;
  ~DeformOutbox();
  DeformOutbox(const DeformOutbox&) = delete;
  DeformOutbox& operator=(const DeformOutbox&) = delete;

  // A server-wide gauge of unwritten notice bytes, kept up to date by every outbox given it (for
  // tests and diagnostics). Set before the first notice; `gauge` must outlive the outbox.
  void set_backlog_gauge(std::atomic<std::int64_t>* gauge) { gauge_ = gauge; }

  // Sizes the frames (FrameSlots::Allocate).
  void AllocateFrames(int num_vertices, std::size_t encoded_bytes = 0, int transform_floats = 0,
                      std::size_t bone_surface_bytes = 0, bool constraints = false) {
    frames_.Allocate(num_vertices, encoded_bytes, transform_floats, bone_surface_bytes,
                     constraints);
  }
  // The frame the next solve fills (FrameSlots::working).
  v1::DeformResponse* working_frame() { return frames_.working(); }
  // The working frame is finished; it goes after the notices added so far.
  void PublishFrame();

  // Queues a notice (its message cut); false when it is a rejection dropped because the backlog
  // is full.
  bool AddNotice(v1::Notice::Kind kind, std::uint64_t sequence, std::uint64_t stiffness_version,
                 const std::string& message, double factor_ms = 0);
  // Whether the backlog is at its count or byte bound: rejections are dropped now (check before
  // building their message), and the stream must not read further requests.
  bool notice_backlog_full() const {
    return notices_.size() >= kMaxNoticeBacklog || backlog_bytes_ >= kMaxNoticeBacklogBytes;
  }
  // Whether the backlog drained to half its bounds (when a stream that stopped reading resumes).
  bool notice_backlog_drained() const {
    return notices_.size() <= kMaxNoticeBacklog / 2 && backlog_bytes_ <= kMaxNoticeBacklogBytes / 2;
  }
  // Serialized bytes of the unwritten notices.
  std::size_t notice_backlog_bytes() const { return backlog_bytes_; }
  // Rejections dropped so far.
  std::uint64_t notices_dropped() const { return notices_dropped_; }

  // The next message to write (the frame when no notice must go before it), or nullptr.
  const v1::DeformResponse* TakeNextWrite();
  // Whether the message last taken is a frame.
  bool frame_in_flight() const { return frame_in_flight_; }

  // Nothing waits to be written (the message in flight aside).
  bool empty() const { return !frames_.has_ready() && notices_.empty(); }

 private:
  FrameSlots frames_;
  void AdjustBacklog(std::int64_t delta);

  std::deque<v1::DeformResponse> notices_;
  std::size_t backlog_bytes_ = 0;
  std::uint64_t notices_dropped_ = 0;
  std::atomic<std::int64_t>* gauge_ = nullptr;
  std::size_t notices_before_frame_ = 0;  // of notices_, those to write before the ready frame
  v1::DeformResponse notice_in_flight_;
  bool frame_in_flight_ = false;
};

}  // namespace deform::service
