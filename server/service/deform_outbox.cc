#include "service/deform_outbox.h"

namespace deform::service {

void DeformOutbox::PublishFrame() {
  frames_.Publish();
  notices_before_frame_ = notices_.size();
}

void DeformOutbox::AddNotice(v1::Notice::Kind kind, std::uint64_t sequence,
                             std::uint64_t stiffness_version, const std::string& message,
                             double factor_ms) {
  v1::Notice* notice = notices_.emplace_back().mutable_notice();
  notice->set_kind(kind);
  notice->set_sequence(sequence);
  notice->set_stiffness_version(stiffness_version);
  notice->set_message(message);
  notice->set_factor_ms(factor_ms);
}

const v1::DeformResponse* DeformOutbox::TakeNextWrite() {
  if (frames_.has_ready() && notices_before_frame_ == 0) {
    frame_in_flight_ = true;
    return frames_.StartWriting();
  }
  if (!notices_.empty()) {
    notice_in_flight_.Swap(&notices_.front());
    notices_.pop_front();
    if (notices_before_frame_ > 0) --notices_before_frame_;
    frame_in_flight_ = false;
    return &notice_in_flight_;
  }
  return nullptr;
}

}  // namespace deform::service
