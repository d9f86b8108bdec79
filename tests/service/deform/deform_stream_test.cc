// The Deform stream through the client library: frames against the core, stiffness switches,
// rejected input, latest-wins, cancellation, unloading and shutdown.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <limits>
#include <string>
#include <thread>
#include <vector>

#include "core/constraints/bone_contacts.h"
#include "core/constraints/bone_reach.h"
#include "core/constraints/skin_constraints.h"
#include "core/geometry/pose.h"
#include "core/io/phantom.h"
#include "core/model/deformation_model.h"
#include "tests/service/support/service_fixture.h"

namespace deform::test_support {
namespace {

using ::testing::HasSubstr;

// The core's result for `spec` on the default phantom model of `vertices`, and its diagonal:
// constrained as the service's default constraints do (the phantom's bones, contacts and volume),
// or with `constrained` false the model's own frame.
struct CoreResult {
  Positions positions;
  double diagonal = 0;
  int clamped = 0;
};

CoreResult CoreDeform(int vertices, const std::string& spec,
                      const ModelOptions& options = ModelOptions::Paper(),
                      bool constrained = true) {
  CoreResult result;
  auto phantom = MakeKneePhantom(vertices);
  EXPECT_TRUE(phantom.ok());
  ModelOptions built = options;  // as the server builds a limb with bones (mesh_loader.cc)
  if (constrained) {
    EXPECT_TRUE(UnanchorReachedSkin(phantom->mesh, phantom->skeleton, phantom->bones,
                                    ConstraintOptions{}, &built)
                    .ok());
  }
  auto model = DeformationModel::Build(phantom->mesh, phantom->skeleton, built);
  EXPECT_TRUE(model.ok()) << model.status().ToString();
  auto terms = ParsePoseSpec(spec, (*model)->skeleton());
  EXPECT_TRUE(terms.ok()) << terms.status().ToString();
  Pose pose;
  auto clamped = PoseFromTerms((*model)->skeleton(), *terms, &pose);
  EXPECT_TRUE(clamped.ok());
  result.clamped = *clamped;
  DeformScratch scratch = (*model)->MakeScratch();
  (*model)->Deform(*(*model)->default_factorization(), pose, &scratch);
  if (constrained) {
    auto bones = BoneContacts::Create(phantom->bones, (*model)->skeleton(), (*model)->mesh(),
                                      (*model)->rigid_bones());
    EXPECT_TRUE(bones.ok()) << bones.status().ToString();
    auto constraints = SkinConstraints::Create(**model, *bones);
    EXPECT_TRUE(constraints.ok()) << constraints.status().ToString();
    ConstraintScratch constraint_scratch = (*constraints)->MakeScratch();
    ConstraintReport report;
    EXPECT_TRUE(
        (*constraints)
            ->Apply(*(*model)->default_factorization(), &scratch, &constraint_scratch, &report));
  }
  result.positions = scratch.positions();
  result.diagonal = (*model)->bounding_box_diagonal();
  return result;
}

double MaxDifference(const std::vector<float>& a, const std::vector<float>& b) {
  double worst = 0;
  for (std::size_t k = 0; k < std::min(a.size(), b.size()); ++k) {
    worst = std::max(worst, std::abs(static_cast<double>(a[k]) - b[k]));
  }
  return worst;
}

// The largest coordinate difference between a frame's float32 positions and the core's result.
double DistanceFromCore(const std::vector<float>& positions, const CoreResult& core) {
  EXPECT_EQ(positions.size(), static_cast<std::size_t>(core.positions.size()));
  double worst = 0;
  for (Eigen::Index i = 0; i < core.positions.rows(); ++i) {
    for (int c = 0; c < 3 && static_cast<std::size_t>(3 * i + c) < positions.size(); ++c) {
      worst = std::max(worst, std::abs(positions[3 * i + c] - core.positions(i, c)));
    }
  }
  return worst;
}

// The Deform stream's tests: every body runs over both transports (the stream handler is one
// for both), except the few that speak gRPC's own API (DeformStreamGrpcTest).
class DeformStreamTest : public ServiceTest, public ::testing::WithParamInterface<Transport> {
 protected:
  void SetUp() override { transport_ = GetParam(); }

  // Opens `count` streams on `mesh_id`, each with its own recorder.
  void OpenStreams(const std::string& mesh_id, int count, bool keep_positions,
                   std::vector<std::unique_ptr<StreamRecorder>>* recorders,
                   std::vector<std::unique_ptr<client::DeformStream>>* streams) {
    for (int s = 0; s < count; ++s) {
      recorders->push_back(std::make_unique<StreamRecorder>(keep_positions));
      streams->push_back(OpenStream(mesh_id, recorders->back()->Callbacks()));
    }
  }
};
class DeformStreamGrpcTest : public ServiceTest {};

INSTANTIATE_TEST_SUITE_P(Transports, DeformStreamTest,
                         ::testing::Values(Transport::kGrpc, Transport::kWebSocket), TransportName);

TEST_P(DeformStreamTest, FrameEqualsTheCoreResultForTheSamePose) {
  StartServer();
  constexpr int kVertices = 2000;
  const std::string mesh_id = LoadPhantom(kVertices);
  StreamRecorder recorder(/*keep_positions=*/true);
  auto stream = OpenStream(mesh_id, recorder.Callbacks());

  const std::vector<std::string> specs = {"knee:flexion:60,hip:flexion:20", "knee:flexion:200",
                                          "knee:x:-30,ankle:y:10", "rest"};
  std::uint64_t sequence = 0;
  for (const std::string& spec : specs) {
    v1::PoseUpdate pose;
    std::string error;
    ASSERT_TRUE(client::ParsePoseAngles(spec, &pose, &error)) << error;
    pose.set_sequence(++sequence);
    pose.set_client_timestamp_ns(1000 + static_cast<std::int64_t>(sequence));
    ASSERT_TRUE(stream->SendPose(pose));
    ASSERT_TRUE(recorder.WaitForFrameWithSequence(sequence)) << spec;
    const v1::DeformFrame frame = recorder.last_frame();
    ASSERT_EQ(frame.sequence(), sequence);
    EXPECT_EQ(frame.client_timestamp_ns(), 1000 + static_cast<std::int64_t>(sequence));
    EXPECT_EQ(frame.stiffness_version(), 0u);
    EXPECT_FALSE(frame.mesh_unloaded());

    const CoreResult core = CoreDeform(kVertices, spec);
    EXPECT_EQ(frame.clamped_angles(), static_cast<std::uint32_t>(core.clamped)) << spec;
    const std::vector<float> positions = client::DecodePositions(frame.positions());
    ASSERT_EQ(positions.size(), static_cast<std::size_t>(core.positions.size()));
    double worst = 0;
    for (Eigen::Index i = 0; i < core.positions.rows(); ++i) {
      for (int c = 0; c < 3; ++c) {
        worst = std::max(worst, std::abs(positions[3 * i + c] - core.positions(i, c)));
      }
    }
    EXPECT_LE(worst, 1e-6 * core.diagonal) << spec;
  }
  EXPECT_EQ(CoreDeform(kVertices, "knee:flexion:200").clamped, 1);
  stream->Close();
  EXPECT_TRUE(stream->Wait().ok());
  ExpectBackgroundStreamAlive();
}

// The linear rotation blend reaches the core: the frame is the core's linear-blend result (from its
// precomputed response), not the quaternion blend's.
TEST_P(DeformStreamTest, LinearBlendFrameEqualsTheCoreResult) {
  StartServer();
  constexpr int kVertices = 1500;
  v1::MethodOptions options;
  options.set_rotation_blend(v1::ROTATION_BLEND_LINEAR);
  v1::MeshSummary summary;
  const std::string mesh_id = LoadPhantom(kVertices, options, &summary);
  EXPECT_EQ(summary.rotation_blend(), v1::ROTATION_BLEND_LINEAR);
  EXPECT_GT(summary.linear_response_bytes(), 0u);
  StreamRecorder recorder(/*keep_positions=*/true);
  auto stream = OpenStream(mesh_id, recorder.Callbacks());
  const std::string spec = "knee:flexion:90,knee:rotation:10";
  v1::PoseUpdate pose;
  std::string error;
  ASSERT_TRUE(client::ParsePoseAngles(spec, &pose, &error)) << error;
  pose.set_sequence(1);
  ASSERT_TRUE(stream->SendPose(pose));
  ASSERT_TRUE(recorder.WaitForFrameWithSequence(1));
  const std::vector<float> positions = client::DecodePositions(recorder.last_frame().positions());

  ModelOptions linear = ModelOptions::Paper();
  linear.rotation_blend = RotationBlend::kLinear;
  const CoreResult core = CoreDeform(kVertices, spec, linear);
  const CoreResult quaternion = CoreDeform(kVertices, spec);
  ASSERT_EQ(positions.size(), static_cast<std::size_t>(core.positions.size()));
  double from_linear = 0, from_quaternion = 0;
  for (Eigen::Index i = 0; i < core.positions.rows(); ++i) {
    for (int c = 0; c < 3; ++c) {
      from_linear = std::max(from_linear, std::abs(positions[3 * i + c] - core.positions(i, c)));
      from_quaternion =
          std::max(from_quaternion, std::abs(positions[3 * i + c] - quaternion.positions(i, c)));
    }
  }
  EXPECT_LE(from_linear, 1e-6 * core.diagonal);
  EXPECT_GT(from_quaternion, 1e-4 * core.diagonal);
  stream->Close();
  EXPECT_TRUE(stream->Wait().ok());
  ExpectBackgroundStreamAlive();
}

TEST_P(DeformStreamTest, StiffnessUpdateSwitchesVersionsWithoutAGap) {
  StartServer();
  const std::string mesh_id = LoadPhantom(3000);
  StreamRecorder recorder(/*keep_positions=*/true);
  auto stream = OpenStream(mesh_id, recorder.Callbacks());
  // A fixed pose, so that only the stiffness changes the frames.
  std::atomic<bool> stop{false};
  std::thread pacer([&] {
    for (std::uint64_t sequence = 1; !stop.load(); ++sequence) {
      if (!stream->SendPose(KneePose(sequence, 90))) break;
      std::this_thread::sleep_for(std::chrono::milliseconds(3));
    }
  });
  ASSERT_TRUE(recorder.WaitForFrames(5));
  v1::StiffnessUpdate stiffness;
  v1::RegionWeight* weight = stiffness.add_region_weights();
  weight->set_joint("knee");
  weight->set_weight(20);
  ASSERT_TRUE(stream->SendStiffness(stiffness));
  ASSERT_TRUE(recorder.WaitForNotice(v1::Notice::KIND_STIFFNESS_APPLIED));
  const std::int64_t at_notice = recorder.frames();
  ASSERT_TRUE(recorder.WaitForFrames(at_notice + 5)) << "frames stopped after the switch";
  stop.store(true);
  pacer.join();
  stream->Close();
  ASSERT_TRUE(stream->Wait().ok());

  const v1::Notice applied = *recorder.FindNotice(v1::Notice::KIND_STIFFNESS_APPLIED);
  EXPECT_EQ(applied.stiffness_version(), 1u);
  EXPECT_GT(applied.factor_ms(), 0);
  EXPECT_FALSE(recorder.FindNotice(v1::Notice::KIND_STIFFNESS_REJECTED).has_value());

  std::uint64_t previous_version = 0;
  bool after_notice = false;
  std::vector<float> before_positions, after_positions;
  int frames_before = 0, frames_after = 0;
  for (const RecordedEvent& event : recorder.events()) {
    if (!event.is_frame) {
      if (event.notice.kind() == v1::Notice::KIND_STIFFNESS_APPLIED) after_notice = true;
      continue;
    }
    const std::uint64_t version = event.frame.stiffness_version();
    EXPECT_GE(version, previous_version);
    previous_version = version;
    EXPECT_EQ(version, after_notice ? 1u : 0u);
    if (after_notice) {
      ++frames_after;
      after_positions = client::DecodePositions(event.frame.positions());
    } else {
      ++frames_before;
      before_positions = client::DecodePositions(event.frame.positions());
    }
  }
  EXPECT_GE(frames_before, 5);
  EXPECT_GE(frames_after, 5);
  // Same pose, stiffer knee region: the surface moved.
  EXPECT_GT(MaxDifference(before_positions, after_positions), 1e-4);
  ExpectBackgroundStreamAlive();
}

TEST_P(DeformStreamTest, NanAngleIsRejectedAndTheStreamGoesOn) {
  StartServer();
  const std::string mesh_id = LoadPhantom(500);
  StreamRecorder recorder;
  auto stream = OpenStream(mesh_id, recorder.Callbacks());
  ASSERT_TRUE(stream->SendPose(KneePose(1, 30)));
  ASSERT_TRUE(recorder.WaitForFrameWithSequence(1));
  ASSERT_TRUE(stream->SendPose(KneePose(2, std::numeric_limits<double>::quiet_NaN())));
  ASSERT_TRUE(recorder.WaitForNotice(v1::Notice::KIND_POSE_REJECTED));
  const v1::Notice rejected = *recorder.FindNotice(v1::Notice::KIND_POSE_REJECTED);
  EXPECT_EQ(rejected.sequence(), 2u);
  EXPECT_THAT(rejected.message(), HasSubstr("finite"));
  ASSERT_TRUE(stream->SendPose(KneePose(3, std::numeric_limits<double>::infinity(), 10)));
  // Wait for pose 3's rejection before sending pose 4: the client keeps only the newest unsent
  // pose, so pose 4 sent at once could replace pose 3 before it leaves.
  ASSERT_TRUE(recorder.WaitUntil([&] {
    int count = 0;
    for (const RecordedEvent& event : recorder.EventsLocked()) {
      count += !event.is_frame && event.notice.kind() == v1::Notice::KIND_POSE_REJECTED;
    }
    return count >= 2;
  }));
  ASSERT_TRUE(stream->SendPose(KneePose(4, 45)));
  ASSERT_TRUE(recorder.WaitForFrameWithSequence(4));
  stream->Close();
  EXPECT_TRUE(stream->Wait().ok());
  int rejections = 0;
  for (const RecordedEvent& event : recorder.events()) {
    if (event.is_frame) {
      EXPECT_NE(event.frame.sequence(), 2u);
    }
    if (!event.is_frame && event.notice.kind() == v1::Notice::KIND_POSE_REJECTED) ++rejections;
  }
  EXPECT_EQ(rejections, 2);
  ExpectBackgroundStreamAlive();
}

TEST_P(DeformStreamTest, UnknownJointIsRejectedInPosesAndStiffness) {
  StartServer();
  const std::string mesh_id = LoadPhantom(500);
  StreamRecorder recorder;
  auto stream = OpenStream(mesh_id, recorder.Callbacks());
  v1::PoseUpdate pose = KneePose(1, 10);
  pose.mutable_angles(0)->set_joint("elbow");
  ASSERT_TRUE(stream->SendPose(pose));
  ASSERT_TRUE(recorder.WaitForNotice(v1::Notice::KIND_POSE_REJECTED));
  EXPECT_THAT(recorder.FindNotice(v1::Notice::KIND_POSE_REJECTED)->message(), HasSubstr("elbow"));

  v1::StiffnessUpdate stiffness;
  v1::JointMaterialUpdate* material = stiffness.add_joint_materials();
  material->set_joint("elbow");
  material->mutable_material()->set_soft(2);
  ASSERT_TRUE(stream->SendStiffness(stiffness));
  ASSERT_TRUE(recorder.WaitForNotice(v1::Notice::KIND_STIFFNESS_REJECTED));
  const v1::Notice rejected = *recorder.FindNotice(v1::Notice::KIND_STIFFNESS_REJECTED);
  EXPECT_EQ(rejected.stiffness_version(), 1u);
  EXPECT_THAT(rejected.message(), HasSubstr("elbow"));

  // Still streaming, still on the default stiffness.
  ASSERT_TRUE(stream->SendPose(KneePose(2, 20)));
  ASSERT_TRUE(recorder.WaitForFrameWithSequence(2));
  EXPECT_EQ(recorder.last_frame().stiffness_version(), 0u);
  stream->Close();
  EXPECT_TRUE(stream->Wait().ok());
  ExpectBackgroundStreamAlive();
}

TEST_F(DeformStreamGrpcTest, FirstMessageMustBeStart) {
  StartServer();
  grpc::ClientContext context;
  auto stream = client_->stub()->Deform(&context);
  v1::DeformRequest request;
  *request.mutable_pose() = KneePose(1, 10);
  stream->Write(request);
  stream->WritesDone();
  v1::DeformResponse response;
  while (stream->Read(&response)) {
  }
  const grpc::Status status = stream->Finish();
  EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_THAT(status.error_message(), HasSubstr("start"));
  ExpectBackgroundStreamAlive();
}

// Every pose the server received is either answered by a frame or counted in the next frame's
// skipped_poses, and the newest pose is always answered.
TEST_F(DeformStreamGrpcTest, LatestPoseWinsAndSkippedPosesAccountForEveryPose) {
  StartServer();
  const std::string mesh_id = LoadPhantom(3000);
  grpc::ClientContext context;
  auto stream = client_->stub()->Deform(&context);
  v1::DeformRequest request;
  request.mutable_start()->set_mesh_id(mesh_id);
  ASSERT_TRUE(stream->Write(request));
  constexpr std::uint64_t kPoses = 300;
  std::vector<v1::DeformFrame> frames;
  std::thread reader([&] {
    v1::DeformResponse response;
    while (stream->Read(&response)) {
      if (response.has_frame()) {
        response.mutable_frame()->clear_positions();
        frames.push_back(response.frame());
      }
    }
  });
  for (std::uint64_t sequence = 1; sequence <= kPoses; ++sequence) {
    *request.mutable_pose() = KneePose(sequence, static_cast<double>(sequence % 120));
    ASSERT_TRUE(stream->Write(request));
  }
  stream->WritesDone();
  reader.join();
  ASSERT_TRUE(stream->Finish().ok());

  ASSERT_FALSE(frames.empty());
  EXPECT_EQ(frames.back().sequence(), kPoses);
  std::uint64_t accounted = 0;
  std::uint64_t previous = 0;
  for (const v1::DeformFrame& frame : frames) {
    EXPECT_GT(frame.sequence(), previous);
    EXPECT_EQ(frame.sequence() - previous - 1, frame.skipped_poses());
    previous = frame.sequence();
    accounted += 1 + frame.skipped_poses();
  }
  EXPECT_EQ(accounted, kPoses);
  ExpectBackgroundStreamAlive();
}

TEST_P(DeformStreamTest, CancelledClientLeavesTheServerHealthy) {
  StartServer();
  const std::string mesh_id = LoadPhantom(500);
  StreamRecorder recorder;
  auto stream = OpenStream(mesh_id, recorder.Callbacks());
  {
    PosePacer pacer(stream.get(), std::chrono::milliseconds(2));
    ASSERT_TRUE(recorder.WaitForFrames(5));
    stream->Cancel();
    EXPECT_EQ(stream->Wait().error_code(), grpc::StatusCode::CANCELLED);
  }
  EXPECT_FALSE(stream->SendPose(KneePose(1000, 10)));
  stream.reset();

  // The server forgets the stream and serves new ones.
  StreamRecorder fresh;
  auto again = OpenStream(mesh_id, fresh.Callbacks());
  ASSERT_TRUE(again->SendPose(KneePose(1, 10)));
  ASSERT_TRUE(fresh.WaitForFrameWithSequence(1));
  again->Close();
  EXPECT_TRUE(again->Wait().ok());
  v1::GetMeshInfoResponse info;
  const auto deadline = std::chrono::steady_clock::now() + kWaitTimeout;
  do {
    ASSERT_TRUE(client_->GetMeshInfo(mesh_id, false, &info).ok());
    if (info.summary().open_streams() == 0) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  } while (std::chrono::steady_clock::now() < deadline);
  EXPECT_EQ(info.summary().open_streams(), 0u);
  ExpectBackgroundStreamAlive();
}

TEST_P(DeformStreamTest, UnloadedMeshKeepsItsStreamsButRefusesNewOnes) {
  StartServer();
  const std::string mesh_id = LoadPhantom(500);
  StreamRecorder recorder;
  auto stream = OpenStream(mesh_id, recorder.Callbacks());
  ASSERT_TRUE(stream->SendPose(KneePose(1, 10)));
  ASSERT_TRUE(recorder.WaitForFrameWithSequence(1));
  EXPECT_FALSE(recorder.last_frame().mesh_unloaded());

  ASSERT_TRUE(client_->UnloadMesh(mesh_id).ok());
  ASSERT_TRUE(stream->SendPose(KneePose(2, 20)));
  ASSERT_TRUE(recorder.WaitForFrameWithSequence(2));
  EXPECT_TRUE(recorder.last_frame().mesh_unloaded());

  StreamRecorder refused;
  auto late = OpenStream(mesh_id, refused.Callbacks());
  EXPECT_EQ(late->Wait().error_code(), grpc::StatusCode::NOT_FOUND);
  v1::GetMeshInfoResponse info;
  EXPECT_EQ(client_->GetMeshInfo(mesh_id, false, &info).error_code(), grpc::StatusCode::NOT_FOUND);

  ASSERT_TRUE(stream->SendPose(KneePose(3, 30)));
  ASSERT_TRUE(recorder.WaitForFrameWithSequence(3));
  stream->Close();
  EXPECT_TRUE(stream->Wait().ok());
  ExpectBackgroundStreamAlive();
}

TEST_P(DeformStreamTest, AnUnloadedMeshKeptAliveByAStreamStillCountsAgainstTheBudget) {
  service::ServerOptions options = TestServerOptions();
  // One 5000-vertex phantom (about 14 MiB) and its stream (about 2 MiB with its constraints'
  // scratch), not two phantoms.
  options.limits.max_memory_bytes = std::size_t{20} << 20;
  StartServer(options);
  const std::string mesh_id = LoadPhantom(5000);
  StreamRecorder recorder;
  auto stream = OpenStream(mesh_id, recorder.Callbacks());
  ASSERT_TRUE(stream->SendPose(KneePose(1, 10)));
  ASSERT_TRUE(recorder.WaitForFrameWithSequence(1));
  ASSERT_TRUE(client_->UnloadMesh(mesh_id).ok());

  // The stream keeps the model in memory: the budget still counts it.
  v1::MeshSummary summary;
  const grpc::Status refused = client_->LoadPhantom(5000, {}, &summary);
  EXPECT_EQ(refused.error_code(), grpc::StatusCode::RESOURCE_EXHAUSTED);
  EXPECT_THAT(refused.error_message(), HasSubstr("by unloaded meshes that streams still use"));

  stream->Close();
  EXPECT_TRUE(stream->Wait().ok());
  // Its last stream has ended: the memory is released.
  grpc::Status loaded;
  for (int attempt = 0; attempt < 100; ++attempt) {
    loaded = client_->LoadPhantom(5000, {}, &summary);
    if (loaded.ok()) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  EXPECT_TRUE(loaded.ok()) << loaded.error_message();
  ExpectBackgroundStreamAlive();
}

TEST_P(DeformStreamTest, HalfCloseAnswersTheLastPoseThenEndsOk) {
  StartServer();
  const std::string mesh_id = LoadPhantom(500);
  StreamRecorder recorder;
  auto stream = OpenStream(mesh_id, recorder.Callbacks());
  for (std::uint64_t sequence = 1; sequence <= 50; ++sequence) {
    ASSERT_TRUE(stream->SendPose(KneePose(sequence, static_cast<double>(sequence))));
  }
  stream->Close();
  EXPECT_FALSE(stream->SendPose(KneePose(51, 0)));
  EXPECT_TRUE(stream->Wait().ok());
  EXPECT_EQ(recorder.last_frame().sequence(), 50u);
  ASSERT_TRUE(recorder.status().has_value());
  EXPECT_TRUE(recorder.status()->ok());
}

TEST_P(DeformStreamTest, ManyStreamsOnOneMeshAllReceiveFrames) {
  StartServer();
  const std::string mesh_id = LoadPhantom(1000);
  constexpr int kStreams = 16;
  std::vector<std::unique_ptr<StreamRecorder>> recorders;
  std::vector<std::unique_ptr<client::DeformStream>> streams;
  OpenStreams(mesh_id, kStreams, /*keep_positions=*/false, &recorders, &streams);
  for (std::uint64_t sequence = 1; sequence <= 20; ++sequence) {
    for (auto& stream : streams) ASSERT_TRUE(stream->SendPose(KneePose(sequence, 3.0 * sequence)));
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  for (int s = 0; s < kStreams; ++s) {
    EXPECT_TRUE(recorders[s]->WaitForFrameWithSequence(20)) << s;
    streams[s]->Close();
  }
  for (auto& stream : streams) EXPECT_TRUE(stream->Wait().ok());
  ExpectBackgroundStreamAlive();
}

// Streams on one mesh whose poses queue together are solved in one pass over the factor
// (FrameTimings.batch_frames > 1), and each stream's frame is still its own pose's core result.
// One worker, so poses sent while it solves queue behind it and form the batch.
TEST_P(DeformStreamTest, StreamsSolvedInOneBatchEachGetTheirOwnPosesFrame) {
  service::ServerOptions options = TestServerOptions();
  options.workers = 1;
  options.batch_frames = 8;
  StartServer(options);
  constexpr int kVertices = 6000;
  constexpr int kStreams = 6;
  const std::string mesh_id = LoadPhantom(kVertices);
  std::vector<std::unique_ptr<StreamRecorder>> recorders;
  std::vector<std::unique_ptr<client::DeformStream>> streams;
  OpenStreams(mesh_id, kStreams, /*keep_positions=*/true, &recorders, &streams);
  std::vector<CoreResult> expected;  // per stream: the knee at 15 * (s + 1) degrees
  for (int s = 0; s < kStreams; ++s) {
    expected.push_back(CoreDeform(kVertices, "knee:flexion:" + std::to_string(15 * (s + 1))));
  }
  std::uint32_t largest_batch = 0;
  for (std::uint64_t round = 1; round <= 30 && largest_batch < 2; ++round) {
    for (int s = 0; s < kStreams; ++s) {
      ASSERT_TRUE(streams[s]->SendPose(KneePose(round, 15.0 * (s + 1))));
    }
    for (int s = 0; s < kStreams; ++s) {
      ASSERT_TRUE(recorders[s]->WaitForFrameWithSequence(round)) << s;
      const v1::DeformFrame frame = recorders[s]->last_frame();
      largest_batch = std::max(largest_batch, frame.timings().batch_frames());
      const CoreResult& core = expected[s];
      EXPECT_LE(DistanceFromCore(client::DecodePositions(frame.positions()), core),
                1e-6 * core.diagonal)
          << "stream " << s << " round " << round << " batch " << frame.timings().batch_frames();
    }
  }
  EXPECT_GE(largest_batch, 2u) << "no two streams' poses were ever solved together";
  for (auto& stream : streams) {
    stream->Close();
    EXPECT_TRUE(stream->Wait().ok());
  }
  ExpectBackgroundStreamAlive();
}

// A mesh with a parallel plan (the threshold lowered to zero) on two workers: its streams' poses
// that queue together are solved as one batch split over both workers (batch_frames > 1 and
// solve_parts 2: the pool runs one such batch at a time, the other worker helping), and each
// stream's frame is still its own pose's core result.
TEST_P(DeformStreamTest, ABatchSplitOverTheWorkersGivesEachStreamItsOwnPosesFrame) {
  service::ServerOptions options = TestServerOptions();
  options.workers = 2;
  options.batch_frames = 8;
  options.parallel_solve_min_factor_bytes = 0;
  StartServer(options);
  constexpr int kVertices = 6000;
  constexpr int kStreams = 6;
  const std::string mesh_id = LoadPhantom(kVertices);
  std::vector<std::unique_ptr<StreamRecorder>> recorders;
  std::vector<std::unique_ptr<client::DeformStream>> streams;
  OpenStreams(mesh_id, kStreams, /*keep_positions=*/true, &recorders, &streams);
  std::vector<CoreResult> expected;  // per stream: the knee at 15 * (s + 1) degrees
  for (int s = 0; s < kStreams; ++s) {
    expected.push_back(CoreDeform(kVertices, "knee:flexion:" + std::to_string(15 * (s + 1))));
  }
  bool split_batch = false;
  for (std::uint64_t round = 1; round <= 30 && !split_batch; ++round) {
    for (int s = 0; s < kStreams; ++s) {
      ASSERT_TRUE(streams[s]->SendPose(KneePose(round, 15.0 * (s + 1))));
    }
    for (int s = 0; s < kStreams; ++s) {
      ASSERT_TRUE(recorders[s]->WaitForFrameWithSequence(round)) << s;
      const v1::DeformFrame frame = recorders[s]->last_frame();
      split_batch =
          split_batch || (frame.timings().batch_frames() > 1 && frame.timings().solve_parts() == 2);
      const CoreResult& core = expected[s];
      EXPECT_LE(DistanceFromCore(client::DecodePositions(frame.positions()), core),
                1e-6 * core.diagonal)
          << "stream " << s << " round " << round << " batch " << frame.timings().batch_frames()
          << " parts " << frame.timings().solve_parts();
    }
  }
  EXPECT_TRUE(split_batch) << "no batch was ever split over the two workers";
  for (auto& stream : streams) {
    stream->Close();
    EXPECT_TRUE(stream->Wait().ok());
  }
  ExpectBackgroundStreamAlive();
}

// With --batch-frames 1 every frame is solved alone.
TEST_P(DeformStreamTest, ABatchLimitOfOneSolvesEveryFrameAlone) {
  service::ServerOptions options = TestServerOptions();
  options.workers = 1;
  options.batch_frames = 1;
  StartServer(options);
  const std::string mesh_id = LoadPhantom(3000);
  constexpr int kStreams = 4;
  std::vector<std::unique_ptr<StreamRecorder>> recorders;
  std::vector<std::unique_ptr<client::DeformStream>> streams;
  OpenStreams(mesh_id, kStreams, /*keep_positions=*/false, &recorders, &streams);
  for (std::uint64_t round = 1; round <= 10; ++round) {
    for (auto& stream : streams) ASSERT_TRUE(stream->SendPose(KneePose(round, 5.0 * round)));
  }
  for (int s = 0; s < kStreams; ++s) {
    ASSERT_TRUE(recorders[s]->WaitForFrameWithSequence(10)) << s;
    for (const RecordedEvent& event : recorders[s]->events()) {
      if (event.is_frame) {
        EXPECT_EQ(event.frame.timings().batch_frames(), 1u);
      }
    }
    streams[s]->Close();
  }
  for (auto& stream : streams) EXPECT_TRUE(stream->Wait().ok());
}

// A lone stream on a server with `workers` workers and a parallel plan for every mesh (the
// threshold lowered to zero): three poses' frames are solved in `parts` parts
// (FrameTimings.solve_parts) and are the core's frames. The fixture's background stream is open
// too, so the service has two streams open.
class LoneFrameSplitTest : public DeformStreamTest {
 protected:
  // `parts`: every frame's solve_parts; with `until_split`, frames are solved (up to thirty) until
  // one is split in `parts` and each one's parts is 1 or `parts` (whether a worker is idle at the
  // moment a frame starts is up to the scheduler).
  void ExpectThreeFramesSolvedIn(int workers, unsigned parts, bool until_split = false) {
    service::ServerOptions options = TestServerOptions();
    options.workers = workers;
    options.parallel_solve_min_factor_bytes = 0;
    StartServer(options);
    constexpr int kVertices = 4000;
    const std::string mesh_id = LoadPhantom(kVertices);
    StreamRecorder recorder(/*keep_positions=*/true);
    auto stream = OpenStream(mesh_id, recorder.Callbacks());
    std::uint64_t sequence = 0;
    bool split = false;
    for (int i = 0; i < (until_split ? 30 : 3) && !(until_split && split); ++i) {
      const int degrees = std::vector<int>{30, 75, 120}[i % 3];
      ASSERT_TRUE(stream->SendPose(KneePose(++sequence, degrees)));
      ASSERT_TRUE(recorder.WaitForFrameWithSequence(sequence));
      const v1::DeformFrame frame = recorder.last_frame();
      split = split || frame.timings().solve_parts() == parts;
      if (until_split) {
        EXPECT_TRUE(frame.timings().solve_parts() == 1 || frame.timings().solve_parts() == parts);
      } else {
        EXPECT_EQ(frame.timings().solve_parts(), parts);
      }
      const CoreResult core = CoreDeform(kVertices, "knee:flexion:" + std::to_string(degrees));
      EXPECT_LE(DistanceFromCore(client::DecodePositions(frame.positions()), core),
                1e-6 * core.diagonal)
          << degrees;
    }
    EXPECT_TRUE(split) << "no frame was solved in " << parts << " parts";
    stream->Close();
    EXPECT_TRUE(stream->Wait().ok());
    ExpectBackgroundStreamAlive();
  }
};

// Fewer streams open than workers (two of three): a lone frame is split over the workers.
INSTANTIATE_TEST_SUITE_P(Transports, LoneFrameSplitTest,
                         ::testing::Values(Transport::kGrpc, Transport::kWebSocket), TransportName);

TEST_P(LoneFrameSplitTest, FramesSplitOverTheWorkersWhileFewerStreamsThanWorkersAreOpen) {
  ExpectThreeFramesSolvedIn(/*workers=*/3, /*parts=*/3);
}

// As many streams open as workers (two of two), but the other stream sends nothing, so the other
// worker is idle when a frame starts (unless the scheduler has not yet let it wait): a lone frame
// is split over it too.
TEST_P(LoneFrameSplitTest, FramesSplitOverAnIdleWorkerAlsoWhileAsManyStreamsAsWorkersAreOpen) {
  ExpectThreeFramesSolvedIn(/*workers=*/2, /*parts=*/2, /*until_split=*/true);
}

// One worker: nothing to split over, every frame solved whole.
TEST_P(LoneFrameSplitTest, FramesAreSolvedWholeOnASingleWorker) {
  ExpectThreeFramesSolvedIn(/*workers=*/1, /*parts=*/1);
}

// With the float32 threshold lowered to every mesh, the phantom's factor is stored in float32 (the
// summary says so, with the probe's error), and its frames, batched, split over the workers or
// alone, stay within 1e-6 of the diagonal of the core's double frames.
TEST_P(DeformStreamTest, AFloat32FactorsFramesStayWithinTheTransportRoundingOfTheCore) {
  service::ServerOptions options = TestServerOptions();
  options.workers = 2;
  options.parallel_solve_min_factor_bytes = 0;
  options.float32_factor_min_bytes = 0;
  StartServer(options);
  constexpr int kVertices = 4000;
  v1::MeshSummary summary;
  const std::string mesh_id = LoadPhantom(kVertices, {}, &summary);
  EXPECT_TRUE(summary.factor_float32());
  EXPECT_GT(summary.float32_probe_error(), 0);
  EXPECT_LE(summary.float32_probe_error(), MaterialFactorization::kFloat32ProbeTolerance);
  std::vector<std::unique_ptr<StreamRecorder>> recorders;
  std::vector<std::unique_ptr<client::DeformStream>> streams;
  OpenStreams(mesh_id, 3, /*keep_positions=*/true, &recorders, &streams);
  std::uint64_t sequence = 0;
  for (const int degrees : {30, 75, 120}) {
    ++sequence;
    for (auto& stream : streams) ASSERT_TRUE(stream->SendPose(KneePose(sequence, degrees)));
    const CoreResult core = CoreDeform(kVertices, "knee:flexion:" + std::to_string(degrees));
    for (std::size_t s = 0; s < streams.size(); ++s) {
      ASSERT_TRUE(recorders[s]->WaitForFrameWithSequence(sequence));
      const v1::DeformFrame frame = recorders[s]->last_frame();
      EXPECT_LE(DistanceFromCore(client::DecodePositions(frame.positions()), core),
                1e-6 * core.diagonal)
          << degrees << " degrees, stream " << s << ", batch " << frame.timings().batch_frames()
          << ", parts " << frame.timings().solve_parts();
    }
  }
  for (auto& stream : streams) {
    stream->Close();
    EXPECT_TRUE(stream->Wait().ok());
  }
  ExpectBackgroundStreamAlive();
}

// By default (64 MiB) a small mesh keeps its factor in double and no probe runs.
TEST_P(DeformStreamTest, ASmallMeshKeepsADoubleFactorByDefault) {
  StartServer();
  v1::MeshSummary summary;
  LoadPhantom(2000, {}, &summary);
  EXPECT_FALSE(summary.factor_float32());
  EXPECT_LT(summary.float32_probe_error(), 0);
}

TEST(DeformServerShutdownTest, ShutdownEndsOpenStreamsPromptly) {
  TestServer server;
  auto client = server.NewClient();
  v1::MeshSummary summary;
  ASSERT_TRUE(client->LoadPhantom(500, {}, &summary).ok());
  StreamRecorder first, second;
  auto stream_a = client->OpenStream(summary.mesh_id(), first.Callbacks());
  auto stream_b = client->OpenStream(summary.mesh_id(), second.Callbacks());
  {
    PosePacer pacer_a(stream_a.get(), std::chrono::milliseconds(3));
    PosePacer pacer_b(stream_b.get(), std::chrono::milliseconds(3));
    ASSERT_TRUE(first.WaitForFrames(3));
    ASSERT_TRUE(second.WaitForFrames(3));
    // The grace period is long; draining must not need it.
    const auto start = std::chrono::steady_clock::now();
    server.server().Shutdown(std::chrono::seconds(120));
    EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::seconds(60));
    EXPECT_EQ(stream_a->Wait().error_code(), grpc::StatusCode::UNAVAILABLE);
    EXPECT_EQ(stream_b->Wait().error_code(), grpc::StatusCode::UNAVAILABLE);
  }
  std::vector<v1::MeshSummary> meshes;
  EXPECT_FALSE(client->ListMeshes(&meshes).ok());
}

}  // namespace
}  // namespace deform::test_support
