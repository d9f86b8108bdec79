#include "core/eval/method_comparison.h"

#include <algorithm>
#include <chrono>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "core/base/median.h"
#include "core/eval/direct_delta_mush.h"
#include "core/eval/optimized_centers.h"
#include "core/eval/skinning.h"

namespace deform {
namespace {

using Clock = std::chrono::steady_clock;

// Runs `frame` `repeat` times; each run's wall time in seconds.
template <typename Frame>
std::vector<double> TimeFrames(int repeat, Frame&& frame) {
  std::vector<double> seconds;
  seconds.reserve(repeat);
  for (int r = 0; r < repeat; ++r) {
    const auto start = Clock::now();
    frame();
    seconds.push_back(std::chrono::duration<double>(Clock::now() - start).count());
  }
  return seconds;
}

bool Solves(Method method) {
  return method == Method::kPaper || method == Method::kPaperLinear || method == Method::kLaplacian;
}

// The model `method` solves with: a variant of the paper model when it needs one (the same regions,
// so the same harmonic weights, anchors and ordering), or null when the paper model serves.
StatusOr<std::shared_ptr<const DeformationModel>> VariantFor(const DeformationModel& paper_model,
                                                             Method method) {
  ModelOptions options = paper_model.options();
  if (method == Method::kLaplacian) {
    options = ModelOptions::PlainLaplacian(paper_model.options());
  } else if (method == Method::kPaperLinear) {
    options.rotation_blend = RotationBlend::kLinear;
  }
  if (method != Method::kLaplacian &&
      options.rotation_blend == paper_model.options().rotation_blend) {
    return std::shared_ptr<const DeformationModel>();
  }
  // The same binding: the paper model's given weights, when it was built with some.
  const std::optional<SkinWeights>& weights = paper_model.given_weights();
  return DeformationModel::Build(paper_model.mesh(), paper_model.skeleton(), options,
                                 weights.has_value() ? &*weights : nullptr);
}

bool Constrained(Method method) {
  return method == Method::kPaper || method == Method::kPaperLinear;
}

// Paper, paper-linear and laplacian: `repeat` frames of the model's Deform(), constrained (paper
// and paper-linear) when `constraints` are given.
Status RunSolvingMethod(const DeformationModel& paper_model, Method method, const Pose& pose,
                        int repeat, const SkinConstraints* constraints, const ToolSet* tools,
                        MethodRun* run) {
  DEFORM_ASSIGN_OR_RETURN(const std::shared_ptr<const DeformationModel> variant,
                          VariantFor(paper_model, method));
  const DeformationModel& model = variant ? *variant : paper_model;
  const MaterialFactorization& factorization = *model.default_factorization();
  run->precompute_seconds = model.precompute_seconds();
  run->factor_seconds = factorization.factor_seconds();
  run->factor_bytes = factorization.factor().bytes();
  if (factorization.linear_response() != nullptr) {
    run->response_bytes = factorization.linear_response()->bytes();
  }
  run->joint_nodes = model.num_joint_nodes();
  run->anchors = static_cast<int>(model.anchor_vertices().size());
  // The variant solves with its own factorization, so it needs constraints of its own.
  std::shared_ptr<const SkinConstraints> variant_constraints;
  if (constraints != nullptr && !Constrained(method)) constraints = nullptr;
  if (tools != nullptr && !tools->empty() &&
      (constraints == nullptr || !constraints->takes_tools())) {
    return Status::InvalidArgument(std::string("tools need constraints that take them, with ") +
                                   "paper or paper-linear, not " + MethodName(method));
  }
  if (constraints != nullptr && variant) {
    DEFORM_ASSIGN_OR_RETURN(
        variant_constraints,
        SkinConstraints::Create(model, constraints->bones_shared(), constraints->options()));
    constraints = variant_constraints.get();
  }
  DeformScratch scratch = model.MakeScratch();
  ConstraintScratch constraint_scratch;
  if (constraints != nullptr) constraint_scratch = constraints->MakeScratch();
  std::vector<double> solve_seconds, constraint_seconds;
  solve_seconds.reserve(repeat);
  constraint_seconds.reserve(repeat);
  run->frame_seconds = Median(TimeFrames(repeat, [&] {
    DeformTimings timings;
    model.Deform(factorization, pose, &scratch, &timings);
    solve_seconds.push_back(timings.solve);
    if (constraints != nullptr) {
      const auto start = Clock::now();
      constraints->Apply(factorization, &scratch, &constraint_scratch, &run->constraints, tools);
      constraint_seconds.push_back(std::chrono::duration<double>(Clock::now() - start).count());
    }
  }));
  run->solve_seconds = Median(solve_seconds);
  if (!constraint_seconds.empty()) run->constraint_seconds = Median(constraint_seconds);
  run->posed = scratch.positions();
  return Status::Ok();
}

// The skinning baselines (LBS, DQS, CoR, DDM) with the paper model's weights: `repeat` frames,
// each the whole frame; the precomputation of CoR and DDM is counted with the model's.
void RunSkinningMethod(const DeformationModel& paper_model, Method method, const Pose& pose,
                       int repeat, MethodRun* run) {
  const Positions& rest = paper_model.mesh().vertices;
  const BoneWeights& weights = paper_model.bone_weights();
  run->precompute_seconds = paper_model.precompute_seconds();
  const auto start = Clock::now();
  RotationCenters centers;
  if (method == Method::kCor) centers = ComputeRotationCenters(paper_model.mesh(), weights);
  DirectDeltaMush mush;
  if (method == Method::kDdm) mush = DirectDeltaMush::Precompute(paper_model.mesh(), weights);
  run->precompute_seconds += std::chrono::duration<double>(Clock::now() - start).count();
  std::vector<RigidTransform> bones;
  DirectDeltaMush::BoneMatrices bone_matrices;
  run->frame_seconds = Median(TimeFrames(repeat, [&] {
    ForwardKinematics(paper_model.skeleton(), pose, &bones);
    switch (method) {
      case Method::kLbs:
        LinearBlendSkinning(rest, weights, bones, &run->posed);
        break;
      case Method::kDqs:
        DualQuaternionSkinning(rest, weights, bones, &run->posed);
        break;
      case Method::kCor:
        OptimizedCentersSkinning(rest, weights, centers, bones, &run->posed);
        break;
      default:
        mush.Deform(bones, &run->posed, &bone_matrices);
        break;
    }
  }));
  run->solve_seconds = run->frame_seconds;
}

}  // namespace

StatusOr<Method> MethodFromName(std::string_view name) {
  for (Method method : {Method::kPaper, Method::kPaperLinear, Method::kLaplacian, Method::kLbs,
                        Method::kDqs, Method::kCor, Method::kDdm}) {
    if (name == MethodName(method)) return method;
  }
  return Status::InvalidArgument("unknown method '" + std::string(name) +
                                 "' (known: paper, paper-linear, laplacian, lbs, dqs, cor, ddm)");
}

const char* MethodName(Method method) {
  switch (method) {
    case Method::kPaper:
      return "paper";
    case Method::kPaperLinear:
      return "paper-linear";
    case Method::kLaplacian:
      return "laplacian";
    case Method::kLbs:
      return "lbs";
    case Method::kDqs:
      return "dqs";
    case Method::kCor:
      return "cor";
    case Method::kDdm:
      return "ddm";
  }
  return "unknown";
}

StatusOr<MethodRun> RunMethod(const TriangleMesh& mesh, const Skeleton& skeleton, Method method,
                              const Pose& pose, int repeat, const ModelOptions& paper_options) {
  DEFORM_ASSIGN_OR_RETURN(auto model, DeformationModel::Build(mesh, skeleton, paper_options));
  return RunMethod(*model, method, pose, repeat);
}

StatusOr<MethodRun> RunMethod(const DeformationModel& paper_model, Method method, const Pose& pose,
                              int repeat, const SkinConstraints* constraints,
                              const ToolSet* tools) {
  repeat = std::max(1, repeat);
  MethodRun run;
  if (Solves(method)) {
    DEFORM_RETURN_IF_ERROR(
        RunSolvingMethod(paper_model, method, pose, repeat, constraints, tools, &run));
  } else {
    if (tools != nullptr && !tools->empty()) {
      return Status::InvalidArgument(std::string("tools need paper or paper-linear, not ") +
                                     MethodName(method));
    }
    RunSkinningMethod(paper_model, method, pose, repeat, &run);
  }
  std::vector<RigidTransform> bones;
  ForwardKinematics(paper_model.skeleton(), pose, &bones);
  Positions skinned;
  LinearBlendSkinning(paper_model.mesh().vertices, paper_model.bone_weights(), bones, &skinned);
  run.quality = MeasureQuality(paper_model.mesh(), run.posed, paper_model.skeleton(), bones,
                               skinned, paper_model.rigid_bones(),
                               constraints != nullptr ? constraints->bones() : nullptr);
  return run;
}

}  // namespace deform
