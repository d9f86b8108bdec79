// DeformOutbox: notices in order, each frame after the notices added before it was published.
#include "service/deform/deform_outbox.h"

#include <gtest/gtest.h>

#include <atomic>
#include <cstdint>
#include <string>
#include <vector>

namespace deform::service {
namespace {

// Publishes a frame for pose `sequence`.
void PublishFrame(DeformOutbox* outbox, std::uint64_t sequence) {
  outbox->working_frame()->mutable_frame()->set_sequence(sequence);
  outbox->working_frame()->mutable_frame()->set_skipped_poses(0);
  outbox->PublishFrame();
}

void AddNotice(DeformOutbox* outbox, const std::string& message) {
  outbox->AddNotice(v1::Notice::KIND_STIFFNESS_APPLIED, 0, 1, message);
}

// Takes and "writes" every message; "F<sequence>" for a frame, the message for a notice.
std::vector<std::string> DrainOutbox(DeformOutbox* outbox) {
  std::vector<std::string> written;
  while (const v1::DeformResponse* next = outbox->TakeNextWrite()) {
    EXPECT_EQ(outbox->frame_in_flight(), next->has_frame());
    written.push_back(next->has_frame() ? "F" + std::to_string(next->frame().sequence())
                                        : next->notice().message());
  }
  return written;
}

TEST(DeformOutboxTest, AFrameGoesAfterTheNoticesAddedBeforeItAndBeforeLaterOnes) {
  DeformOutbox outbox;
  outbox.AllocateFrames(1);
  AddNotice(&outbox, "a");
  PublishFrame(&outbox, 1);
  AddNotice(&outbox, "b");
  EXPECT_EQ(DrainOutbox(&outbox), (std::vector<std::string>{"a", "F1", "b"}));
  EXPECT_TRUE(outbox.empty());
}

TEST(DeformOutboxTest, AFrameWithNoNoticeBeforeItGoesFirst) {
  DeformOutbox outbox;
  outbox.AllocateFrames(1);
  PublishFrame(&outbox, 1);
  AddNotice(&outbox, "a");
  EXPECT_EQ(DrainOutbox(&outbox), (std::vector<std::string>{"F1", "a"}));
}

TEST(DeformOutboxTest, ANewerFrameReplacesTheReadyOneAfterAllNoticesBeforeIt) {
  DeformOutbox outbox;
  outbox.AllocateFrames(1);
  AddNotice(&outbox, "a");
  PublishFrame(&outbox, 1);
  AddNotice(&outbox, "applied");
  PublishFrame(&outbox, 2);  // frame 1 is superseded, never written
  EXPECT_EQ(DrainOutbox(&outbox), (std::vector<std::string>{"a", "applied", "F2"}));
}

TEST(DeformOutboxTest, InterleavedWritesKeepTheOrder) {
  DeformOutbox outbox;
  outbox.AllocateFrames(1);
  PublishFrame(&outbox, 1);
  ASSERT_TRUE(outbox.TakeNextWrite()->has_frame());  // frame 1 in flight
  AddNotice(&outbox, "applied");
  PublishFrame(&outbox, 2);
  EXPECT_FALSE(outbox.empty());
  EXPECT_EQ(DrainOutbox(&outbox), (std::vector<std::string>{"applied", "F2"}));
  EXPECT_EQ(outbox.TakeNextWrite(), nullptr);
}

TEST(DeformOutboxTest, TheBacklogIsFullAtItsLimit) {
  DeformOutbox outbox;
  for (std::size_t k = 0; k + 1 < DeformOutbox::kMaxNoticeBacklog; ++k) AddNotice(&outbox, "n");
  EXPECT_FALSE(outbox.notice_backlog_full());
  AddNotice(&outbox, "n");
  EXPECT_TRUE(outbox.notice_backlog_full());
  outbox.TakeNextWrite();
  EXPECT_FALSE(outbox.notice_backlog_full());
}

TEST(DeformOutboxTest, TheBacklogIsBoundedInBytesForEveryKind) {
  DeformOutbox outbox;
  std::atomic<std::int64_t> gauge{0};
  outbox.set_backlog_gauge(&gauge);
  const std::string long_message(100'000, 'm');  // cut to kMaxNoticeMessageBytes
  int added = 0;
  for (int k = 0; k < 10'000; ++k) {
    const auto kind =
        k % 2 == 0 ? v1::Notice::KIND_POSE_REJECTED : v1::Notice::KIND_STIFFNESS_REJECTED;
    if (outbox.AddNotice(kind, 0, 1, long_message)) ++added;
  }
  EXPECT_TRUE(outbox.notice_backlog_full());
  EXPECT_LT(added, 300);
  EXPECT_EQ(outbox.notices_dropped(), static_cast<std::uint64_t>(10'000 - added));
  EXPECT_LE(outbox.notice_backlog_bytes(),
            DeformOutbox::kMaxNoticeBacklogBytes + 2 * DeformOutbox::kMaxNoticeMessageBytes);
  EXPECT_EQ(static_cast<std::size_t>(gauge.load()), outbox.notice_backlog_bytes());
  // An applied-stiffness notice is never dropped (it separates two versions' frames).
  EXPECT_TRUE(outbox.AddNotice(v1::Notice::KIND_STIFFNESS_APPLIED, 0, 2, "applied"));
  const v1::DeformResponse* first = outbox.TakeNextWrite();
  ASSERT_NE(first, nullptr);
  EXPECT_EQ(first->notice().message().size(), DeformOutbox::kMaxNoticeMessageBytes);
  while (!outbox.notice_backlog_drained()) outbox.TakeNextWrite();
  EXPECT_FALSE(outbox.notice_backlog_full());
  while (outbox.TakeNextWrite() != nullptr) {
  }
  EXPECT_EQ(gauge.load(), 0);
}

TEST(DeformOutboxTest, NoticesCarryTheirFields) {
  DeformOutbox outbox;
  outbox.AddNotice(v1::Notice::KIND_POSE_REJECTED, 7, 3, "pose 7: bad", 1.5);
  const v1::DeformResponse* next = outbox.TakeNextWrite();
  ASSERT_NE(next, nullptr);
  ASSERT_TRUE(next->has_notice());
  EXPECT_EQ(next->notice().kind(), v1::Notice::KIND_POSE_REJECTED);
  EXPECT_EQ(next->notice().sequence(), 7u);
  EXPECT_EQ(next->notice().stiffness_version(), 3u);
  EXPECT_EQ(next->notice().message(), "pose 7: bad");
  EXPECT_EQ(next->notice().factor_ms(), 1.5);
}

}  // namespace
}  // namespace deform::service
