// PendingPoseSlot: latest wins, skipped poses, and when the solve task is posted.
#include "service/deform/pending_pose_slot.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <optional>

namespace deform::service {
namespace {

PoseInput PoseWithSequence(std::uint64_t sequence) {
  PoseInput pose;
  pose.sequence = sequence;
  return pose;
}

TEST(PendingPoseSlotTest, OnlyTheFirstOfferOfAnIdleStreamPostsTheTask) {
  PendingPoseSlot slot;
  EXPECT_TRUE(slot.idle());
  PoseInput pose = PoseWithSequence(1);
  EXPECT_TRUE(slot.Offer(&pose));
  EXPECT_FALSE(slot.idle());
  pose = PoseWithSequence(2);
  EXPECT_FALSE(slot.Offer(&pose));  // queued already
  slot.BeginRun();
  EXPECT_TRUE(slot.running());
  pose = PoseWithSequence(3);
  EXPECT_FALSE(slot.Offer(&pose));  // running: the run posts again if needed
}

TEST(PendingPoseSlotTest, LatestWinsAndTakeReportsThePosesItReplaced) {
  PendingPoseSlot slot;
  for (std::uint64_t sequence = 1; sequence <= 3; ++sequence) {
    PoseInput pose = PoseWithSequence(sequence);
    slot.Offer(&pose);
  }
  slot.BeginRun();
  PoseInput working;
  const std::optional<std::uint64_t> skipped = slot.Take(&working);
  ASSERT_TRUE(skipped.has_value());
  EXPECT_EQ(*skipped, 2u);
  EXPECT_EQ(working.sequence, 3u);
  EXPECT_FALSE(slot.has_pending());
  EXPECT_FALSE(slot.Take(&working).has_value());

  PoseInput pose = PoseWithSequence(4);
  slot.Offer(&pose);
  EXPECT_EQ(slot.Take(&working), std::optional<std::uint64_t>(0));  // the count starts again
}

TEST(PendingPoseSlotTest, ARunWithAPosePendingIsPostedAgainUnlessTheStreamEnds) {
  PendingPoseSlot slot;
  PoseInput pose = PoseWithSequence(1);
  slot.Offer(&pose);
  slot.BeginRun();
  PoseInput working;
  ASSERT_TRUE(slot.Take(&working).has_value());
  pose = PoseWithSequence(2);
  slot.Offer(&pose);  // arrives during the solve
  EXPECT_TRUE(slot.EndRun(/*may_continue=*/true));
  EXPECT_FALSE(slot.idle());
  EXPECT_FALSE(slot.running());

  slot.BeginRun();
  EXPECT_FALSE(slot.EndRun(/*may_continue=*/false));  // ending: the pose stays unsolved
  EXPECT_TRUE(slot.idle());
  EXPECT_TRUE(slot.has_pending());
}

TEST(PendingPoseSlotTest, ARunWithNothingPendingGoesIdle) {
  PendingPoseSlot slot;
  PoseInput pose = PoseWithSequence(1);
  slot.Offer(&pose);
  slot.BeginRun();
  PoseInput working;
  ASSERT_TRUE(slot.Take(&working).has_value());
  EXPECT_FALSE(slot.EndRun(/*may_continue=*/true));
  EXPECT_TRUE(slot.idle());
  pose = PoseWithSequence(2);
  EXPECT_TRUE(slot.Offer(&pose));
}

TEST(PendingPoseSlotTest, BuffersCirculateInsteadOfBeingCopied) {
  PendingPoseSlot slot;
  PoseInput first, second, working;
  first.angles.resize(4);
  second.angles.resize(4);
  const PoseTerm* first_buffer = first.angles.data();
  slot.Offer(&first);  // `first` now holds the slot's empty buffer
  slot.Offer(&second);
  EXPECT_EQ(second.angles.data(), first_buffer);  // the replaced pose's buffer comes back
  slot.BeginRun();
  ASSERT_TRUE(slot.Take(&working).has_value());
  EXPECT_EQ(working.angles.size(), 4u);
}

}  // namespace
}  // namespace deform::service
