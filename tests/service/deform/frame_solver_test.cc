// FrameSolver against the core, and the per-frame path of the Deform stream's parts (pending pose,
// solve, outbox) without allocation.
#include "service/deform/frame_solver.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <cstring>
#include <memory>
#include <optional>

#include "core/io/phantom.h"
#include "service/deform/deform_outbox.h"
#include "service/deform/pending_pose_slot.h"
#include "tests/allocation_counter.h"

namespace deform::service {
namespace {

std::shared_ptr<const DeformationModel> PhantomModel(int vertices) {
  auto phantom = MakeKneePhantom(vertices);
  EXPECT_TRUE(phantom.ok());
  auto model = DeformationModel::Build(phantom->mesh, phantom->skeleton, ModelOptions::Paper());
  EXPECT_TRUE(model.ok()) << model.status().ToString();
  return std::move(*model);
}

// A knee flexion of `degrees` (the phantom's joint 1, its first degree of freedom).
PoseInput KneeFlexion(std::uint64_t sequence, double degrees) {
  PoseInput input;
  input.sequence = sequence;
  input.client_timestamp_ns = 1000 + static_cast<std::int64_t>(sequence);
  input.arrival = std::chrono::steady_clock::now();
  PoseTerm term;
  term.joint = 1;
  term.dof = 0;
  term.degrees = degrees;
  input.angles.push_back(term);
  return input;
}

float DecodeFloat(const std::string& bytes, std::size_t index) {
  float value;
  std::memcpy(&value, bytes.data() + 4 * index, 4);  // little-endian hosts only, as the encoder
  return value;
}

TEST(FrameSolverTest, FrameCarriesTheCoreResultAndTheStamp) {
  const auto model = PhantomModel(500);
  FrameSolver solver(*model);
  v1::DeformFrame frame;
  FrameStamp stamp;
  stamp.stiffness_version = 4;
  stamp.skipped_poses = 2;
  stamp.mesh_unloaded = true;
  const PoseInput input = KneeFlexion(7, 60);
  ASSERT_TRUE(solver.Solve(input, *model->default_factorization(), stamp, &frame).ok());

  Pose pose;
  ASSERT_TRUE(PoseFromTerms(model->skeleton(), input.angles, &pose).ok());
  DeformScratch scratch = model->MakeScratch();
  model->Deform(*model->default_factorization(), pose, &scratch);
  const int vertices = model->mesh().num_vertices();
  ASSERT_EQ(frame.positions().size(), static_cast<std::size_t>(vertices) * 12);
  for (int i = 0; i < vertices; ++i) {
    for (int c = 0; c < 3; ++c) {
      ASSERT_EQ(DecodeFloat(frame.positions(), 3 * i + c),
                static_cast<float>(scratch.positions()(i, c)));
    }
  }
  EXPECT_EQ(frame.sequence(), 7u);
  EXPECT_EQ(frame.client_timestamp_ns(), 1007);
  EXPECT_EQ(frame.stiffness_version(), 4u);
  EXPECT_EQ(frame.skipped_poses(), 2u);
  EXPECT_TRUE(frame.mesh_unloaded());
  EXPECT_EQ(frame.clamped_angles(), 0u);
  EXPECT_GE(frame.timings().queue_ms(), 0);
}

TEST(FrameSolverTest, AnAngleBeyondTheRangeIsClampedAndCounted) {
  const auto model = PhantomModel(300);
  FrameSolver solver(*model);
  v1::DeformFrame frame;
  ASSERT_TRUE(solver.Solve(KneeFlexion(1, 200), *model->default_factorization(), {}, &frame).ok());
  EXPECT_EQ(frame.clamped_angles(), 1u);
}

TEST(FrameSolverTest, ABadPoseLeavesTheFrameUntouched) {
  const auto model = PhantomModel(300);
  FrameSolver solver(*model);
  v1::DeformFrame frame;
  frame.set_sequence(1);
  PoseInput input = KneeFlexion(2, 30);
  input.angles.front().joint = 99;
  const Status status = solver.Solve(input, *model->default_factorization(), {}, &frame);
  EXPECT_EQ(status.code(), StatusCode::kInvalidArgument);
  EXPECT_EQ(frame.sequence(), 1u);
}

// One frame as the stream makes it: offer a pose, run the solve task, publish, write. Once the
// buffers have their sizes, nothing allocates.
TEST(FrameSolverTest, TheStreamsPerFramePathAllocatesNothing) {
  const auto model = PhantomModel(500);
  FrameSolver solver(*model);
  PendingPoseSlot poses;
  DeformOutbox outbox;
  outbox.AllocateFrames(model->mesh().num_vertices());
  PoseInput staging, solving;
  const auto frame_cycle = [&](std::uint64_t sequence) {
    // Refilled as PoseInputFromProto does: the three buffers circulate, keeping their capacity.
    PoseTerm knee;
    knee.joint = 1;
    knee.dof = 0;
    knee.degrees = static_cast<double>(sequence % 90);
    staging.sequence = sequence;
    staging.angles.assign(1, knee);
    poses.Offer(&staging);
    poses.BeginRun();
    const std::optional<std::uint64_t> skipped = poses.Take(&solving);
    ASSERT_TRUE(skipped.has_value());
    FrameStamp stamp;
    stamp.skipped_poses = *skipped;
    ASSERT_TRUE(solver
                    .Solve(solving, *model->default_factorization(), stamp,
                           outbox.working_frame()->mutable_frame())
                    .ok());
    outbox.PublishFrame();
    poses.EndRun(true);
    ASSERT_NE(outbox.TakeNextWrite(), nullptr);
  };
  for (std::uint64_t sequence = 1; sequence <= 3; ++sequence) frame_cycle(sequence);  // warm-up
  const long before = test_support::AllocationCount();
  for (std::uint64_t sequence = 4; sequence <= 20; ++sequence) frame_cycle(sequence);
  EXPECT_EQ(test_support::AllocationCount() - before, 0);
}

}  // namespace
}  // namespace deform::service
