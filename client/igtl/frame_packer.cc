#include "igtl/frame_packer.h"

#include <utility>

namespace deform::igtl_bridge {

FramePacker::FramePacker(Pack pack, Publish publish)
    : pack_(std::move(pack)), publish_(std::move(publish)), thread_([this] { Loop(); }) {}

FramePacker::~FramePacker() { Stop(); }

void FramePacker::Offer(const deform::v1::DeformFrame& frame) {
  std::lock_guard<std::mutex> lock(mu_);
  if (stopping_) return;
  if (has_pending_) ++skipped_;
  pending_.CopyFrom(frame);
  has_pending_ = true;
  wake_.notify_one();
}

void FramePacker::Stop() {
  {
    std::lock_guard<std::mutex> lock(mu_);
    stopping_ = true;
    wake_.notify_one();
  }
  if (thread_.joinable()) thread_.join();
}

long FramePacker::skipped() {
  std::lock_guard<std::mutex> lock(mu_);
  return skipped_;
}

void FramePacker::Loop() {
  deform::v1::DeformFrame frame;
  while (true) {
    {
      std::unique_lock<std::mutex> lock(mu_);
      wake_.wait(lock, [&] { return has_pending_ || stopping_; });
      if (stopping_) return;
      frame.Swap(&pending_);
      has_pending_ = false;
    }
    publish_(std::make_shared<const std::string>(pack_(frame)));
  }
}

}  // namespace deform::igtl_bridge
