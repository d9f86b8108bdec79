#include "core/model/deformation_model.h"

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <string>
#include <thread>
#include <vector>

#include "core/io/mesh_io.h"
#include "core/io/phantom.h"
#include "tests/allocation_counter.h"
#include "tests/core/model/model_test_util.h"
#include "tests/core/model/shared_leg_model.h"
#include "tests/shared_data.h"

namespace deform {
namespace {

using test_support::BuildPhantomModel;
using test_support::MaxDistance;
using test_support::PoseFromSpec;

Positions DeformOnce(const DeformationModel& model, const Pose& pose,
                     const MaterialFactorization* factorization = nullptr) {
  DeformScratch scratch = model.MakeScratch();
  model.Deform(factorization ? *factorization : *model.default_factorization(), pose, &scratch);
  return scratch.positions();
}

TEST(DeformationModel, RestPoseReproducesThePhantom) {
  auto model = BuildPhantomModel();
  const Positions posed = DeformOnce(*model, Pose::Rest(model->skeleton()));
  EXPECT_LT(MaxDistance(posed, model->mesh().vertices), 1e-9 * model->bounding_box_diagonal());
}

TEST(DeformationModel, RestPoseReproducesTheSharedLeg) {
  DEFORM_SHARED_LEG_MODEL(model);
  EXPECT_EQ(model->num_joint_nodes(), 3);  // knee, ankle, ball
  const Positions posed = DeformOnce(*model, Pose::Rest(model->skeleton()));
  EXPECT_LT(MaxDistance(posed, model->mesh().vertices), 1e-5 * model->bounding_box_diagonal());
}

TEST(DeformationModel, RigidMotionOfTheSkeletonMovesTheMeshRigidly) {
  auto model = BuildPhantomModel();
  Pose pose = Pose::Rest(model->skeleton());
  pose.root.rotation =
      Eigen::Quaterniond(Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()));
  pose.root.translation = Eigen::Vector3d(0.5, -2, 3);
  const Positions posed = DeformOnce(*model, pose);
  Positions expected(model->mesh().num_vertices(), 3);
  for (int i = 0; i < expected.rows(); ++i) {
    expected.row(i) = pose.root.Apply(model->mesh().vertices.row(i).transpose()).transpose();
  }
  EXPECT_LT(MaxDistance(posed, expected), 1e-9 * model->bounding_box_diagonal());
}

TEST(DeformationModel, FarFromTheKneeTheSkinFollowsItsBone) {
  auto model = BuildPhantomModel();
  const Pose pose = PoseFromSpec(model->skeleton(), "knee:flexion:90");
  const Positions posed = DeformOnce(*model, pose);
  std::vector<RigidTransform> bones;
  ForwardKinematics(model->skeleton(), pose, &bones);
  // Every vertex of a rigid zone, not only the anchors.
  double worst = 0;
  int rigid = 0;
  for (int i = 0; i < model->mesh().num_vertices(); ++i) {
    const int bone = model->rigid_bones()[i];
    if (bone < 0) continue;
    ++rigid;
    const Eigen::Vector3d target = bones[bone].Apply(model->mesh().vertices.row(i).transpose());
    worst = std::max(worst, (posed.row(i).transpose() - target).norm());
  }
  EXPECT_GT(rigid, model->mesh().num_vertices() / 2);
  EXPECT_LT(worst, 1e-3 * model->bounding_box_diagonal());
}

TEST(DeformationModel, SparseSolveMatchesADenseSolve) {
  auto model = BuildPhantomModel(300);
  const auto& factorization = *model->default_factorization();
  const Pose pose = PoseFromSpec(model->skeleton(), "knee:flexion:70,knee:rotation:10");
  DeformScratch scratch = model->MakeScratch();
  model->AssembleRightHandSide(factorization, pose, &scratch);
  const Eigen::MatrixXd rhs = scratch.solution;
  model->SolveInPlace(factorization, &scratch);

  const Eigen::MatrixXd dense = Eigen::MatrixXd(model->NormalMatrix(factorization));
  ASSERT_LT((dense - dense.transpose()).norm(), 1e-9 * dense.norm());
  const Eigen::MatrixXd expected = dense.llt().solve(rhs);
  EXPECT_LT((Eigen::MatrixXd(scratch.solution) - expected).norm(), 1e-9 * expected.norm());
}

TEST(DeformationModel, RefactorizationAfterAStiffnessChangeEqualsAFreshFactorization) {
  const JointMaterial stiff{9.0, 2.5, 6.0};
  auto model = BuildPhantomModel();
  Stiffness stiffness;
  stiffness.joint_materials.push_back({1, stiff});  // the knee
  auto refactored = model->Factorize(stiffness);
  ASSERT_TRUE(refactored.ok()) << refactored.status().ToString();

  ModelOptions options = ModelOptions::Paper();
  options.default_material = stiff;
  auto fresh = BuildPhantomModel(2000, options);

  const Pose pose = PoseFromSpec(model->skeleton(), "knee:flexion:100");
  const Positions a = DeformOnce(*model, pose, refactored->get());
  const Positions b = DeformOnce(*fresh, pose);
  EXPECT_LT(MaxDistance(a, b), 1e-10 * model->bounding_box_diagonal());
  // And the stiffness matters: the default factorization gives another shape.
  EXPECT_GT(MaxDistance(a, DeformOnce(*model, pose)), 1e-6 * model->bounding_box_diagonal());
}

TEST(DeformationModel, AFrameAllocatesNothing) {
  auto model = BuildPhantomModel();
  const Pose pose = PoseFromSpec(model->skeleton(), "knee:flexion:45");
  DeformScratch scratch = model->MakeScratch();
  DeformTimings timings;
  model->Deform(*model->default_factorization(), pose, &scratch, &timings);  // warm
  const long before = test_support::AllocationCount();
  for (int frame = 0; frame < 10; ++frame) {
    model->Deform(*model->default_factorization(), pose, &scratch, &timings);
  }
  EXPECT_EQ(test_support::AllocationCount() - before, 0);
}

// Deform() refuses a factorization or scratch made by another model: false and nothing written in
// release builds, an assertion in debug builds.
TEST(DeformationModel, RefusesAFactorizationOrScratchOfAnotherModel) {
  auto model = BuildPhantomModel(600);
  auto other = BuildPhantomModel(600);  // the same mesh, yet another model
  const Pose pose = PoseFromSpec(model->skeleton(), "knee:flexion:45");
  const MaterialFactorization& own = *model->default_factorization();
  const MaterialFactorization& foreign = *other->default_factorization();
  DeformScratch scratch = model->MakeScratch();
  DeformScratch foreign_scratch = other->MakeScratch();
  EXPECT_TRUE(model->Owns(own, scratch));
  EXPECT_FALSE(model->Owns(foreign, scratch));
  EXPECT_FALSE(model->Owns(own, foreign_scratch));
  EXPECT_FALSE(model->Owns(own, DeformScratch{}));
#ifdef NDEBUG
  scratch.solution.setConstant(7);
  DeformTimings timings{-1, -1};
  EXPECT_FALSE(model->Deform(foreign, pose, &scratch, &timings));
  EXPECT_FALSE(model->Deform(own, pose, &foreign_scratch, &timings));
  DeformScratch empty;
  EXPECT_FALSE(model->Deform(own, pose, &empty, &timings));
  EXPECT_FALSE(model->AssembleRightHandSide(foreign, pose, &scratch));
  EXPECT_FALSE(model->SolveInPlace(foreign, &scratch));
  EXPECT_TRUE((scratch.solution.array() == 7).all());  // nothing written
  EXPECT_EQ(timings.solve, -1);
#else
  EXPECT_DEATH(model->Deform(foreign, pose, &scratch), "another model");
  EXPECT_DEATH(model->Deform(own, pose, &foreign_scratch), "another model");
#endif
  EXPECT_TRUE(model->Deform(own, pose, &scratch));
  EXPECT_TRUE(other->Deform(foreign, pose, &foreign_scratch));
  EXPECT_EQ(scratch.positions(), foreign_scratch.positions());
}

// A batch's frames: one pose per spec, each pose's frame solved alone by Deform(), a scratch per
// frame, and the pointer arrays DeformBatch takes (into the vectors, which are never resized).
struct BatchFrames {
  BatchFrames(const DeformationModel& model, const std::vector<std::string>& specs) {
    for (const std::string& spec : specs) {
      poses.push_back(PoseFromSpec(model.skeleton(), spec));
      expected.push_back(DeformOnce(model, poses.back()));
      scratches.push_back(model.MakeScratch());
    }
    for (const Pose& pose : poses) pose_pointers.push_back(&pose);
    for (DeformScratch& scratch : scratches) scratch_pointers.push_back(&scratch);
  }
  BatchFrames(const BatchFrames&) = delete;
  BatchFrames& operator=(const BatchFrames&) = delete;

  // Expects the first `count` scratches to hold the frames solved alone, to 1e-12 of the diagonal.
  void ExpectSolvedAlone(const DeformationModel& model, int count,
                         const std::string& context = "") const {
    for (int f = 0; f < count; ++f) {
      EXPECT_LE(MaxDistance(scratches[f].positions(), expected[f]),
                1e-12 * model.bounding_box_diagonal())
          << context << "frame " << f << " of " << count;
    }
  }

  std::vector<Pose> poses;
  std::vector<Positions> expected;
  std::vector<DeformScratch> scratches;
  std::vector<const Pose*> pose_pointers;
  std::vector<DeformScratch*> scratch_pointers;
};

// `count` specs, each made by `spec` from its frame's index.
template <typename Spec>
std::vector<std::string> Specs(int count, Spec&& spec) {
  std::vector<std::string> specs;
  for (int f = 0; f < count; ++f) specs.push_back(spec(f));
  return specs;
}

// The shared leg's batches: joint 1 bent by 15 degrees more in each of `count` frames.
std::vector<std::string> LegBendSpecs(int count) {
  return Specs(count, [](int f) { return "1:x:" + std::to_string(15 * f); });
}

// Frames solved in one batch (one pass over the factor for all their columns) equal the frames
// solved one by one to 1e-12 of the diagonal, for every batch size up to the largest, with
// different poses in one batch and with nothing allocated per batch.
TEST(DeformationModel, ABatchOfFramesEqualsTheFramesSolvedOneByOne) {
  auto model = BuildPhantomModel();
  const MaterialFactorization& factorization = *model->default_factorization();
  const int most = DeformationModel::kMaxBatchFrames;
  BatchFrames frames(*model,
                     Specs(most, [](int f) { return "knee:flexion:" + std::to_string(8 * f); }));
  const Pose* const* pose_pointers = frames.pose_pointers.data();
  DeformScratch* const* scratch_pointers = frames.scratch_pointers.data();
  DeformBatchScratch batch = model->MakeBatchScratch(most);
  EXPECT_EQ(batch.max_frames, most);
  for (int count = 1; count <= most; ++count) {
    const long before = test_support::AllocationCount();
    ASSERT_TRUE(model->DeformBatch(factorization, pose_pointers, scratch_pointers, count, &batch));
    EXPECT_EQ(test_support::AllocationCount() - before, 0) << "count " << count;
    frames.ExpectSolvedAlone(*model, count);
  }
  EXPECT_EQ(model->MakeBatchScratch(1000).max_frames, most);
  EXPECT_EQ(model->MakeBatchScratch(0).max_frames, 1);
#ifdef NDEBUG
  DeformBatchScratch small = model->MakeBatchScratch(2);
  EXPECT_FALSE(model->DeformBatch(factorization, pose_pointers, scratch_pointers, 3, &small));
  EXPECT_FALSE(model->DeformBatch(factorization, pose_pointers, scratch_pointers, 0, &small));
  auto other = BuildPhantomModel();
  DeformBatchScratch foreign = other->MakeBatchScratch(2);
  EXPECT_FALSE(model->DeformBatch(factorization, pose_pointers, scratch_pointers, 2, &foreign));
#endif
}

TEST(DeformationModel, ABatchOnTheSharedLegEqualsTheFramesSolvedOneByOne) {
  DEFORM_SHARED_LEG_MODEL(model);
  const MaterialFactorization& factorization = *model->default_factorization();
  const int count = 8;
  BatchFrames frames(*model, LegBendSpecs(count));
  DeformBatchScratch batch = model->MakeBatchScratch(count);
  ASSERT_TRUE(model->DeformBatch(factorization, frames.pose_pointers.data(),
                                 frames.scratch_pointers.data(), count, &batch));
  frames.ExpectSolvedAlone(*model, count);
}

// A frame solved on several threads (DeformParallel: the right-hand side by ranges, the solve by
// subtrees) equals Deform()'s to 1e-12 of the diagonal for 2 to 4 parts, on a team of threads and
// on one thread, and allocates nothing on the calling thread.
TEST(DeformationModel, AFrameSolvedOnSeveralThreadsEqualsTheSerialFrame) {
  auto model = BuildPhantomModel();
  const MaterialFactorization& factorization = *model->default_factorization();
  for (const char* spec : {"knee:flexion:70", "knee:flexion:20,knee:rotation:10"}) {
    const Pose pose = PoseFromSpec(model->skeleton(), spec);
    const Positions expected = DeformOnce(*model, pose);
    for (const int parts : {2, 3, 4}) {
      const ParallelSolvePlan plan = factorization.factor().PlanParallel(parts);
      ASSERT_EQ(plan.parts, parts);
      std::vector<double> work(factorization.factor().WorkSizeParallel(plan));
      ThreadTeam team(parts);
      SerialRunner serial;
      for (ParallelRunner* runner :
           {static_cast<ParallelRunner*>(&team), static_cast<ParallelRunner*>(&serial)}) {
        DeformScratch scratch = model->MakeScratch();
        const long before = test_support::AllocationCount();
        ASSERT_TRUE(
            model->DeformParallel(factorization, pose, &scratch, plan, work.data(), runner));
        if (runner == &serial) {
          EXPECT_EQ(test_support::AllocationCount() - before, 0);
        }
        EXPECT_LE(MaxDistance(scratch.positions(), expected),
                  1e-12 * model->bounding_box_diagonal())
            << spec << ", " << parts << " parts";
      }
    }
  }
}

TEST(DeformationModel, AFrameOfTheSharedLegSolvedOnTwoThreadsEqualsTheSerialFrame) {
  DEFORM_SHARED_LEG_MODEL(model);
  const MaterialFactorization& factorization = *model->default_factorization();
  const ParallelSolvePlan plan = factorization.factor().PlanParallel(2);
  ASSERT_EQ(plan.parts, 2);
  std::vector<double> work(factorization.factor().WorkSizeParallel(plan));
  ThreadTeam team(2);
  DeformScratch scratch = model->MakeScratch();
  for (const int degrees : {0, 45, 110}) {
    const Pose pose = PoseFromSpec(model->skeleton(), "1:x:" + std::to_string(degrees));
    ASSERT_TRUE(model->DeformParallel(factorization, pose, &scratch, plan, work.data(), &team));
    EXPECT_LE(MaxDistance(scratch.positions(), DeformOnce(*model, pose)),
              1e-12 * model->bounding_box_diagonal())
        << degrees;
  }
}

// A batch solved on several threads (DeformBatchParallel: each frame's right-hand side on one
// thread, the batched solve by subtrees) equals the frames solved one by one to 1e-12 of the
// diagonal, for every batch size and 2 or 3 parts, on a team of threads and on one thread (which
// allocates nothing); a batch scratch made without the plan is refused.
TEST(DeformationModel, ABatchSolvedOnSeveralThreadsEqualsTheFramesSolvedOneByOne) {
  auto model = BuildPhantomModel();
  const MaterialFactorization& factorization = *model->default_factorization();
  const int most = DeformationModel::kMaxBatchFrames;
  BatchFrames frames(*model, Specs(most, [](int f) {
    return "knee:flexion:" + std::to_string(7 * f) + ",knee:rotation:" + std::to_string(f);
  }));
  const Pose* const* pose_pointers = frames.pose_pointers.data();
  DeformScratch* const* scratch_pointers = frames.scratch_pointers.data();
  for (const int parts : {2, 3}) {
    const ParallelSolvePlan plan = factorization.factor().PlanParallel(parts);
    ASSERT_EQ(plan.parts, parts);
    DeformBatchScratch batch = model->MakeBatchScratch(most, &plan);
    EXPECT_EQ((batch.solve_work.size() + batch.rotated.size()) * sizeof(double),
              model->BatchScratchBytes(most, &plan));
    EXPECT_EQ(batch.rotated.size(), most * model->general_rows().rotated_size());
    EXPECT_GE(model->BatchScratchBytes(most, &plan), model->BatchScratchBytes(most));
    ThreadTeam team(parts);
    SerialRunner serial;
    for (ParallelRunner* runner :
         {static_cast<ParallelRunner*>(&team), static_cast<ParallelRunner*>(&serial)}) {
      for (int count = 1; count <= most; ++count) {
        for (int f = 0; f < count; ++f) frames.scratches[f].solution.setConstant(std::nan(""));
        const long before = test_support::AllocationCount();
        ASSERT_TRUE(model->DeformBatchParallel(factorization, pose_pointers, scratch_pointers,
                                               count, &batch, plan, runner));
        if (runner == &serial) {
          EXPECT_EQ(test_support::AllocationCount() - before, 0) << "count " << count;
        }
        frames.ExpectSolvedAlone(*model, count, std::to_string(parts) + " parts, ");
      }
    }
  }
#ifdef NDEBUG
  const ParallelSolvePlan plan = factorization.factor().PlanParallel(3);
  DeformBatchScratch serial_only = model->MakeBatchScratch(most);
  SerialRunner serial;
  EXPECT_FALSE(model->DeformBatchParallel(factorization, pose_pointers, scratch_pointers, most,
                                          &serial_only, plan, &serial));
#endif
}

TEST(DeformationModel, ABatchOfTheSharedLegOnTwoThreadsEqualsTheFramesSolvedOneByOne) {
  DEFORM_SHARED_LEG_MODEL(model);
  const MaterialFactorization& factorization = *model->default_factorization();
  const ParallelSolvePlan plan = factorization.factor().PlanParallel(2);
  ASSERT_EQ(plan.parts, 2);
  const int count = 8;
  BatchFrames frames(*model, LegBendSpecs(count));
  DeformBatchScratch batch = model->MakeBatchScratch(count, &plan);
  ThreadTeam team(2);
  ASSERT_TRUE(model->DeformBatchParallel(factorization, frames.pose_pointers.data(),
                                         frames.scratch_pointers.data(), count, &batch, plan,
                                         &team));
  frames.ExpectSolvedAlone(*model, count);
}

TEST(DeformationModel, ThreadsShareOneModelAndFactorization) {
  auto model = BuildPhantomModel();
  const Pose pose = PoseFromSpec(model->skeleton(), "knee:flexion:60");
  const Positions expected = DeformOnce(*model, pose);
  std::vector<Positions> results(4);
  std::vector<std::thread> threads;
  for (auto& result : results) {
    threads.emplace_back([&] {
      DeformScratch scratch = model->MakeScratch();
      for (int frame = 0; frame < 20; ++frame) {
        model->Deform(*model->default_factorization(), pose, &scratch);
      }
      result = scratch.positions();
    });
  }
  for (auto& t : threads) t.join();
  for (const auto& result : results) EXPECT_EQ(result, expected);
}

TEST(DeformationModel, RefusesAComponentThatCannotBeAnchored) {
  // A small tetrahedron floating at the knee centre lies wholly inside the knee's joint region:
  // no vertex of it is in a bone's rigid zone.
  auto phantom = MakeKneePhantom(600);
  TriangleMesh mesh = phantom->mesh;
  const int n = mesh.num_vertices();
  const Eigen::Vector3d knee = phantom->skeleton.joint(1).rest_position;
  mesh.vertices.conservativeResize(n + 4, 3);
  mesh.vertices.row(n) = (knee + Eigen::Vector3d(0.05, 0, 0)).transpose();
  mesh.vertices.row(n + 1) = (knee + Eigen::Vector3d(0, 0.05, 0)).transpose();
  mesh.vertices.row(n + 2) = (knee + Eigen::Vector3d(0, 0, 0.05)).transpose();
  mesh.vertices.row(n + 3) = knee.transpose();
  const int f = mesh.num_triangles();
  mesh.triangles.conservativeResize(f + 4, 3);
  mesh.triangles.row(f) << n, n + 1, n + 2;
  mesh.triangles.row(f + 1) << n, n + 3, n + 1;
  mesh.triangles.row(f + 2) << n + 1, n + 3, n + 2;
  mesh.triangles.row(f + 3) << n + 2, n + 3, n;
  auto model = DeformationModel::Build(mesh, phantom->skeleton, ModelOptions::Paper());
  ASSERT_FALSE(model.ok());
  EXPECT_EQ(model.status().code(), StatusCode::kInvalidArgument);
  EXPECT_NE(model.status().message().find("component"), std::string::npos)
      << model.status().message();
}

TEST(DeformationModel, RefusesBadMeshesAndOptions) {
  auto phantom = MakeKneePhantom(600);
  TriangleMesh nan_mesh = phantom->mesh;
  nan_mesh.vertices(5, 1) = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(DeformationModel::Build(nan_mesh, phantom->skeleton, {}).status().code(),
            StatusCode::kInvalidArgument);

  ModelOptions limited;
  limited.limits.max_vertices = 100;
  EXPECT_EQ(DeformationModel::Build(phantom->mesh, phantom->skeleton, limited).status().code(),
            StatusCode::kResourceExhausted);

  ModelOptions bad_radius;
  bad_radius.regions.explicit_radius = {{1, -2.0}};
  EXPECT_EQ(DeformationModel::Build(phantom->mesh, phantom->skeleton, bad_radius).status().code(),
            StatusCode::kInvalidArgument);
  bad_radius.regions.explicit_radius = {{0, 1.0}};  // the hip is a root: it has no region
  EXPECT_EQ(DeformationModel::Build(phantom->mesh, phantom->skeleton, bad_radius).status().code(),
            StatusCode::kInvalidArgument);
}

TEST(DeformationModel, RefusesAJointNodeBalanceOutOfRange) {
  auto phantom = MakeKneePhantom(600);
  for (double balance :
       {0.0, -1.0, ModelOptions::kMaxJointNodeBalance * 2, std::numeric_limits<double>::quiet_NaN(),
        std::numeric_limits<double>::infinity()}) {
    ModelOptions options;
    options.joint_node_balance = balance;
    auto model = DeformationModel::Build(phantom->mesh, phantom->skeleton, options);
    ASSERT_FALSE(model.ok()) << balance;
    EXPECT_EQ(model.status().code(), StatusCode::kInvalidArgument) << balance;
    EXPECT_NE(model.status().message().find("joint_node_balance"), std::string::npos)
        << model.status().message();
  }
  ModelOptions largest;
  largest.joint_node_balance = ModelOptions::kMaxJointNodeBalance;
  EXPECT_TRUE(DeformationModel::Build(phantom->mesh, phantom->skeleton, largest).ok());
}

TEST(DeformationModel, RefusesBadStiffness) {
  auto model = BuildPhantomModel(600);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  std::vector<Stiffness> bad(5);
  bad[0].joint_materials = {{1, {nan, 1, 1}}};
  bad[1].joint_materials = {{0, {1, 1, 1}}};  // the hip has no region
  bad[2].vertex_weights = {{1 << 20, 1.0}};   // no such vertex
  bad[3].vertex_weights = {{3, -1.0}};        // negative
  bad[4].region_weights = {{1, 1e9}};         // absurdly stiff
  for (const Stiffness& s : bad) {
    auto f = model->Factorize(s);
    ASSERT_FALSE(f.ok());
    EXPECT_EQ(f.status().code(), StatusCode::kInvalidArgument) << f.status().ToString();
  }
  Stiffness good;
  good.vertex_weights = {{3, 20.0}};
  good.region_weights = {{1, 0.5}};
  EXPECT_TRUE(model->Factorize(good).ok());
}

TEST(DeformationModel, ReportsValidationAndThePrecomputationBeforeFactorizing) {
  auto phantom = MakeKneePhantom(600);
  std::vector<std::string> calls;
  BuildHooks hooks;
  hooks.validated = [&] {
    calls.push_back("validated");
    return Status::Ok();
  };
  hooks.precomputed = [&] { calls.push_back("precomputed"); };
  auto model = DeformationModel::Build(phantom->mesh, phantom->skeleton, {}, hooks);
  ASSERT_TRUE(model.ok());
  EXPECT_EQ(calls, (std::vector<std::string>{"validated", "precomputed"}));

  calls.clear();
  ModelOptions limited;
  limited.limits.max_vertices = 10;
  EXPECT_FALSE(DeformationModel::Build(phantom->mesh, phantom->skeleton, limited, hooks).ok());
  EXPECT_TRUE(calls.empty());  // not reached for input refused by validation
}

TEST(DeformationModel, TheValidatedHookCanStopTheBuild) {
  auto phantom = MakeKneePhantom(600);
  bool precomputed = false;
  BuildHooks hooks;
  hooks.validated = [] { return Status::ResourceExhausted("no room"); };
  hooks.precomputed = [&] { precomputed = true; };
  auto model = DeformationModel::Build(phantom->mesh, phantom->skeleton, {}, hooks);
  EXPECT_EQ(model.status().ToString(), "RESOURCE_EXHAUSTED: no room");
  EXPECT_FALSE(precomputed);
}

TEST(DeformationModel, ACancelledBuildStopsAtTheEndOfThePhaseInProgress) {
  auto phantom = MakeKneePhantom(600);
  CancelToken parent;
  CancelToken token(&parent);
  BuildHooks hooks;
  hooks.cancel = &token;
  // Cancelled (through its parent) while the binding is about to start: nothing more is built.
  bool precomputed = false;
  hooks.validated = [&] {
    parent.Cancel();
    return Status::Ok();
  };
  hooks.precomputed = [&] { precomputed = true; };
  auto stopped = DeformationModel::Build(phantom->mesh, phantom->skeleton, {}, hooks);
  EXPECT_EQ(stopped.status().ToString(), "FAILED_PRECONDITION: cancelled during validation");
  EXPECT_FALSE(precomputed);

  // Cancelled once the precomputation is done: the numeric factorization is not interrupted, the
  // build stops after it.
  CancelToken late;
  hooks.cancel = &late;
  hooks.validated = {};
  hooks.precomputed = [&] { late.Cancel(); };
  auto after_factor = DeformationModel::Build(phantom->mesh, phantom->skeleton, {}, hooks);
  EXPECT_EQ(after_factor.status().ToString(),
            "FAILED_PRECONDITION: cancelled during the numeric factorization");

  CancelToken never;
  hooks.cancel = &never;
  hooks.precomputed = {};
  EXPECT_TRUE(DeformationModel::Build(phantom->mesh, phantom->skeleton, {}, hooks).ok());
}

TEST(DeformationModel, EstimatedBytesAddTheFactorToTheGeometry) {
  auto model = BuildPhantomModel(600);
  const std::size_t before = DeformationModel::EstimateBytesBeforeBuild(
      model->mesh().num_vertices(), model->mesh().num_triangles());
  const std::size_t geometry = DeformationModel::kBytesPerVertex * model->mesh().num_vertices() +
                               DeformationModel::kBytesPerTriangle * model->mesh().num_triangles();
  // The rigid rows' sums (3 doubles a row of L'^T) and bones (an int a row, a byte a vertex),
  // and the general rows' plan with its slots' weights (a double a slot).
  const std::size_t n = model->mesh().num_vertices();
  const std::size_t rows = n + model->num_joint_nodes();
  const std::size_t rigid_rows = rows * 3 * sizeof(double) + rows * sizeof(int) + n;
  const GeneralRowsPlan& plan = model->general_rows();
  const std::size_t general_rows = plan.bytes() + plan.slot_count() * sizeof(double);
  EXPECT_GT(plan.slot_count(), 0);
  EXPECT_EQ(model->EstimatedBytes(), geometry + model->default_factorization()->factor().bytes() +
                                         rigid_rows + general_rows);
  // Before the build the factor is predicted, from above: admission errs towards refusing.
  EXPECT_GT(before, geometry + model->default_factorization()->factor().bytes());
}

TEST(DeformationModel, ScratchAndFactorizationBytesAreWhatAStreamAllocates) {
  auto model = BuildPhantomModel(600);
  const DeformScratch scratch = model->MakeScratch();
  const std::size_t allocated =
      scratch.bone_transforms.size() * sizeof(scratch.bone_transforms[0]) +
      scratch.slot_rotations.size() * sizeof(scratch.slot_rotations[0]) +
      static_cast<std::size_t>(scratch.solution.size() + scratch.rotated_deltas.size()) *
          sizeof(double) +
      (scratch.signed_quaternions.size() + scratch.rotated_slots.size()) * sizeof(double) +
      scratch.solve_work.size() * sizeof(double);
  EXPECT_EQ(model->ScratchBytes(), allocated);
  Stiffness stiffer;
  stiffer.joint_materials.push_back({1, JointMaterial{9.0, 2.5, 6.0}});  // the knee
  auto other = model->Factorize(stiffer);
  ASSERT_TRUE(other.ok()) << other.status().ToString();
  const std::size_t rows = model->mesh().num_vertices() + model->num_joint_nodes();
  EXPECT_EQ((*other)->right_hand_side_bytes(),
            (rows * 3 + model->general_rows().slot_count()) * sizeof(double));
  EXPECT_EQ(model->FactorizationBytes(),
            (*other)->factor().bytes() + (*other)->right_hand_side_bytes());
}

TEST(DeformationModel, BuildPhasesAreTheCancellablePhasesInOrder) {
  auto model = BuildPhantomModel(600);
  std::vector<std::string> names;
  double total = 0;
  for (const DeformationModel::BuildPhase& phase : model->build_phases()) {
    names.push_back(phase.name);
    EXPECT_GE(phase.seconds, 0) << phase.name;
    total += phase.seconds;
  }
  EXPECT_EQ(names, (std::vector<std::string>{
                       "validation", "the mesh's adjacency", "the binding", "the joint regions",
                       "the harmonic weights", "the Laplacian system", "the binding report",
                       "the symbolic analysis", "the numeric factorization"}));
  // The phases cover the build: precomputation and factorization, validation besides.
  EXPECT_GE(total, model->precompute_seconds());
  EXPECT_NEAR(model->build_phases().back().seconds,
              model->default_factorization()->factor_seconds(), 1e-12);
}

TEST(DeformationModel, TheEstimateBeforeTheBuildGrowsFasterThanTheMesh) {
  // A 2,000,000-vertex mesh needs more than 4 GiB (the default budget): refused before the build.
  EXPECT_GT(DeformationModel::EstimateBytesBeforeBuild(2'000'000, 4'000'000), std::size_t{4} << 30);
  EXPECT_GT(DeformationModel::EstimateBytesBeforeBuild(200'000, 400'000),
            2 * DeformationModel::EstimateBytesBeforeBuild(100'000, 200'000));
}

TEST(DeformationModel, ExplicitRegionRadiusIsUsed) {
  ModelOptions options = ModelOptions::Paper();
  options.regions.explicit_radius = {{1, 0.3}};
  auto small = BuildPhantomModel(2000, options);
  auto automatic = BuildPhantomModel(2000);
  ASSERT_EQ(small->joint_regions().regions.size(), 1u);
  EXPECT_DOUBLE_EQ(small->joint_regions().regions[0].radius, 0.3);
  EXPECT_LT(small->joint_regions().regions[0].vertices.size(),
            automatic->joint_regions().regions[0].vertices.size());
  // The automatic radius is 1.5 limb radii; the phantom's knee is about 0.5 dm thick.
  EXPECT_NEAR(automatic->joint_regions().regions[0].limb_radius, 0.55, 0.1);
}

}  // namespace
}  // namespace deform
