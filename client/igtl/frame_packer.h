// Packs the stream's frames into OpenIGTLink messages on a thread of its own, latest wins.
//
// The deform stream's frame callback runs on gRPC's thread: packing there (a full POLYDATA of the
// 26k leg rebuilds 51,840 cells per frame) would hold the stream back whenever packing is slower
// than the frame rate, and the frames would then queue in the stream behind it, seconds of them.
// Offer only keeps the newest frame; the packing thread packs whatever is newest when it is free
// and hands the bytes to `publish` (the ReceiverHub), so frames that packing cannot keep up with
// are skipped, never queued.
//
// Thread safety: Offer from any thread; `pack` and `publish` run on the packing thread only.
#pragma once

#include <condition_variable>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <thread>

#include "deform/v1/deform.pb.h"

namespace deform::igtl_bridge {

class FramePacker {
 public:
  using Pack = std::function<std::string(const deform::v1::DeformFrame&)>;
  using Publish = std::function<void(std::shared_ptr<const std::string>)>;

  FramePacker(Pack pack, Publish publish);
  ~FramePacker();  // Stop()
  FramePacker(const FramePacker&) = delete;
  FramePacker& operator=(const FramePacker&) = delete;

  // The newest frame, replacing one not yet packed.
  void Offer(const deform::v1::DeformFrame& frame);
  // Finishes the frame being packed, drops one waiting, and joins the thread.
  void Stop();
  // Frames replaced before they were packed, so far.
  long skipped();

 private:
  void Loop();

  const Pack pack_;
  const Publish publish_;
  std::mutex mu_;
  std::condition_variable wake_;
  deform::v1::DeformFrame pending_;  // guarded by mu_
  bool has_pending_ = false;         // guarded by mu_
  bool stopping_ = false;            // guarded by mu_
  long skipped_ = 0;                 // guarded by mu_
  std::thread thread_;
};

}  // namespace deform::igtl_bridge
