#include "service/deform/deform_outbox.h"

namespace deform::service {

DeformOutbox::~DeformOutbox() { AdjustBacklog(-static_cast<std::int64_t>(backlog_bytes_)); }

void DeformOutbox::AdjustBacklog(std::int64_t delta) {
  backlog_bytes_ = static_cast<std::size_t>(static_cast<std::int64_t>(backlog_bytes_) + delta);
  if (gauge_ != nullptr && delta != 0) gauge_->fetch_add(delta, std::memory_order_relaxed);
}

void DeformOutbox::PublishFrame() {
  frames_.Publish();
  notices_before_frame_ = notices_.size();
}

bool DeformOutbox::AddNotice(v1::Notice::Kind kind, std::uint64_t sequence,
                             std::uint64_t stiffness_version, const std::string& message,
                             double factor_ms) {
  if (kind != v1::Notice::KIND_STIFFNESS_APPLIED && notice_backlog_full()) {
    ++notices_dropped_;
    return false;
  }
  v1::DeformResponse& response = notices_.emplace_back();
  v1::Notice* notice = response.mutable_notice();
  notice->set_kind(kind);
  notice->set_sequence(sequence);
  notice->set_stiffness_version(stiffness_version);
  if (message.size() <= kMaxNoticeMessageBytes) {
    notice->set_message(message);
  } else {
    notice->set_message(message.substr(0, kMaxNoticeMessageBytes - 3) + "...");
  }
  notice->set_factor_ms(factor_ms);
  AdjustBacklog(static_cast<std::int64_t>(response.ByteSizeLong()));
  return true;
}

const v1::DeformResponse* DeformOutbox::TakeNextWrite() {
  if (frames_.has_ready() && notices_before_frame_ == 0) {
    frame_in_flight_ = true;
    return frames_.StartWriting();
  }
  if (!notices_.empty()) {
    AdjustBacklog(-static_cast<std::int64_t>(notices_.front().ByteSizeLong()));
    notice_in_flight_.Swap(&notices_.front());
    notices_.pop_front();
    if (notices_before_frame_ > 0) --notices_before_frame_;
    frame_in_flight_ = false;
    return &notice_in_flight_;
  }
  return nullptr;
}

}  // namespace deform::service
