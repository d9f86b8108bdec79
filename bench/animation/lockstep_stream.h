// One Deform stream driven in lockstep: send a pose, wait for the frame that answers it, then the
// next. No pose is ever superseded, so every pose of an animation gets its own frame.
#pragma once

#include <condition_variable>
#include <cstdint>
#include <memory>
#include <mutex>
#include <string>

#include "lib/deform_client.h"

namespace deform::animation {

struct AnsweredPose {
  deform::v1::DeformFrame frame;
  double round_trip_ms = 0;  // from the send to the frame's arrival in the client's callback
};

class LockstepStream {
 public:
  // Opens the stream on `mesh_id` (errors such as NOT_FOUND surface in the first Exchange).
  LockstepStream(client::DeformClient& client, const std::string& mesh_id);
  // Half-closes and waits for the stream's end.
  ~LockstepStream();
  LockstepStream(const LockstepStream&) = delete;
  LockstepStream& operator=(const LockstepStream&) = delete;

  // Sends `pose` (its sequence and client timestamp are set here) and waits up to `timeout_ms` for
  // its frame. INVALID_ARGUMENT with the server's message when the pose is rejected,
  // DEADLINE_EXCEEDED on timeout, the stream's status when it ends first.
  grpc::Status Exchange(deform::v1::PoseUpdate pose, int timeout_ms, AnsweredPose* answer);

  // Half-closes and waits up to `timeout_ms` for the stream's final status.
  grpc::Status Finish(int timeout_ms);

 private:
  // The state the stream's callbacks (gRPC threads) share with the caller; `mu` guards every
  // other field. Shared-owned so that a callback arriving after this object is gone finds it alive.
  struct Shared {
    std::mutex mu;
    std::condition_variable changed;
    std::uint64_t awaited = 0;  // the sequence Exchange waits for
    bool answered = false;
    bool rejected = false;
    std::string rejection;
    deform::v1::DeformFrame frame;
    std::int64_t arrival_ns = 0;
    bool done = false;
    grpc::Status final_status;
  };

  std::shared_ptr<Shared> shared_;
  std::unique_ptr<client::DeformStream> stream_;
  std::uint64_t next_sequence_ = 1;
  bool finished_ = false;
};

}  // namespace deform::animation
