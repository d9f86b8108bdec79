// FrameSlots: the rotation of the working, ready and writing frames, and skipped poses of
// superseded frames.
#include "service/deform/frame_slots.h"

#include <gtest/gtest.h>

#include <cstdint>

#include "tests/allocation_counter.h"

namespace deform::service {
namespace {

void Fill(FrameSlots* slots, std::uint64_t sequence, std::uint64_t skipped) {
  v1::DeformFrame* frame = slots->working()->mutable_frame();
  frame->set_sequence(sequence);
  frame->set_skipped_poses(skipped);
}

TEST(FrameSlotsTest, APublishedFrameIsTheOneWritten) {
  FrameSlots slots;
  slots.Allocate(10);
  EXPECT_FALSE(slots.has_ready());
  Fill(&slots, 1, 0);
  slots.Publish();
  EXPECT_TRUE(slots.has_ready());
  const v1::DeformResponse* writing = slots.StartWriting();
  EXPECT_FALSE(slots.has_ready());
  EXPECT_EQ(writing->frame().sequence(), 1u);
  EXPECT_EQ(writing->frame().positions().size(), 120u);
  EXPECT_NE(writing, slots.working());
}

TEST(FrameSlotsTest, ASupersededFrameCountsItselfAndItsSkippedPosesAsSkipped) {
  FrameSlots slots;
  slots.Allocate(1);
  Fill(&slots, 3, 2);  // pose 3, having replaced poses 1 and 2
  slots.Publish();
  Fill(&slots, 5, 1);  // pose 5, having replaced pose 4
  slots.Publish();     // frame 3 was never written
  const v1::DeformResponse* writing = slots.StartWriting();
  EXPECT_EQ(writing->frame().sequence(), 5u);
  EXPECT_EQ(writing->frame().skipped_poses(), 4u);  // poses 1 to 4
}

TEST(FrameSlotsTest, TheWritingFrameStaysIntactWhileNewFramesAreProduced) {
  FrameSlots slots;
  slots.Allocate(1);
  Fill(&slots, 1, 0);
  slots.Publish();
  const v1::DeformResponse* writing = slots.StartWriting();
  for (std::uint64_t sequence = 2; sequence <= 6; ++sequence) {
    EXPECT_NE(slots.working(), writing);
    Fill(&slots, sequence, 0);
    slots.Publish();
  }
  EXPECT_EQ(writing->frame().sequence(), 1u);
  EXPECT_EQ(slots.StartWriting()->frame().sequence(), 6u);
}

TEST(FrameSlotsTest, RotatingFramesAllocatesNothing) {
  FrameSlots slots;
  slots.Allocate(1000);
  const long before = test_support::AllocationCount();
  for (std::uint64_t sequence = 1; sequence <= 100; ++sequence) {
    Fill(&slots, sequence, 0);
    slots.Publish();
    if (sequence % 3 == 0) slots.StartWriting();
  }
  EXPECT_EQ(test_support::AllocationCount() - before, 0);
}

}  // namespace
}  // namespace deform::service
