#include "core/eval/method_comparison.h"

#include <algorithm>
#include <chrono>
#include <string>
#include <vector>

#include "core/eval/skinning.h"

namespace deform {
namespace {

using Clock = std::chrono::steady_clock;

double Median(std::vector<double> values) {
  std::sort(values.begin(), values.end());
  return values[values.size() / 2];
}

}  // namespace

StatusOr<Method> MethodFromName(std::string_view name) {
  if (name == "paper") return Method::kPaper;
  if (name == "paper-linear") return Method::kPaperLinear;
  if (name == "laplacian") return Method::kLaplacian;
  if (name == "lbs") return Method::kLbs;
  if (name == "dqs") return Method::kDqs;
  return Status::InvalidArgument("unknown method '" + std::string(name) +
                                 "' (known: paper, paper-linear, laplacian, lbs, dqs)");
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
  }
  return "unknown";
}

StatusOr<MethodRun> RunMethod(const TriangleMesh& mesh, const Skeleton& skeleton, Method method,
                              const Pose& pose, int repeat, const ModelOptions& paper_options) {
  DEFORM_ASSIGN_OR_RETURN(auto model, DeformationModel::Build(mesh, skeleton, paper_options));
  return RunMethod(*model, method, pose, repeat);
}

StatusOr<MethodRun> RunMethod(const DeformationModel& paper_model, Method method, const Pose& pose,
                              int repeat) {
  repeat = std::max(1, repeat);
  MethodRun run;
  run.precompute_seconds = paper_model.precompute_seconds();
  std::vector<double> frame_seconds;
  frame_seconds.reserve(repeat);

  if (method == Method::kPaper || method == Method::kPaperLinear || method == Method::kLaplacian) {
    // A variant of the paper model when the method needs one: the same regions (so the same
    // harmonic weights), anchors and ordering.
    std::shared_ptr<const DeformationModel> variant;
    const DeformationModel* model = &paper_model;
    ModelOptions variant_options = paper_model.options();
    if (method == Method::kLaplacian) {
      variant_options = ModelOptions::PlainLaplacian(paper_model.options());
    } else if (method == Method::kPaperLinear) {
      variant_options.rotation_blend = RotationBlend::kLinear;
    }
    if (method == Method::kLaplacian ||
        variant_options.rotation_blend != paper_model.options().rotation_blend) {
      DEFORM_ASSIGN_OR_RETURN(
          variant,
          DeformationModel::Build(paper_model.mesh(), paper_model.skeleton(), variant_options));
      model = variant.get();
      run.precompute_seconds = model->precompute_seconds();
    }
    const auto& factorization = *model->default_factorization();
    run.factor_seconds = factorization.factor_seconds();
    run.factor_bytes = factorization.factor().bytes();
    if (factorization.linear_response() != nullptr) {
      run.response_bytes = factorization.linear_response()->bytes();
    }
    run.joint_nodes = model->num_joint_nodes();
    run.anchors = static_cast<int>(model->anchor_vertices().size());
    DeformScratch scratch = model->MakeScratch();
    std::vector<double> solve_seconds;
    solve_seconds.reserve(repeat);
    for (int r = 0; r < repeat; ++r) {
      const auto start = Clock::now();
      DeformTimings timings;
      model->Deform(factorization, pose, &scratch, &timings);
      frame_seconds.push_back(std::chrono::duration<double>(Clock::now() - start).count());
      solve_seconds.push_back(timings.solve);
    }
    run.solve_seconds = Median(solve_seconds);
    run.posed = scratch.positions();
  } else {
    std::vector<RigidTransform> bones;
    for (int r = 0; r < repeat; ++r) {
      const auto start = Clock::now();
      ForwardKinematics(paper_model.skeleton(), pose, &bones);
      if (method == Method::kLbs) {
        LinearBlendSkinning(paper_model.mesh().vertices, paper_model.bone_weights(), bones,
                            &run.posed);
      } else {
        DualQuaternionSkinning(paper_model.mesh().vertices, paper_model.bone_weights(), bones,
                               &run.posed);
      }
      frame_seconds.push_back(std::chrono::duration<double>(Clock::now() - start).count());
    }
  }
  run.frame_seconds = Median(frame_seconds);
  if (method == Method::kLbs || method == Method::kDqs) run.solve_seconds = run.frame_seconds;

  std::vector<RigidTransform> bones;
  ForwardKinematics(paper_model.skeleton(), pose, &bones);
  Positions skinned;
  LinearBlendSkinning(paper_model.mesh().vertices, paper_model.bone_weights(), bones, &skinned);
  run.quality = MeasureQuality(paper_model.mesh(), run.posed, paper_model.skeleton(), bones,
                               skinned, paper_model.rigid_bones());
  return run;
}

}  // namespace deform
