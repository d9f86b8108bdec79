// Runs one deformation method (the paper's or a baseline) on a mesh and pose and measures it:
// what `deformctl deform` prints, what the quality tests compare, and what the benchmarks time.
#pragma once

#include <cstddef>
#include <memory>
#include <string_view>

#include "core/constraints/skin_constraints.h"
#include "core/eval/quality.h"
#include "core/model/deformation_model.h"

namespace deform {

enum class Method {
  kPaper,        // joint centre nodes + material weights (METHOD.md), quaternion rotation blend
  kPaperLinear,  // the same with the linear rotation blend: METHOD.md's fast path, no solve
  kLaplacian,    // plain Laplacian: no joint node, W = I
  kLbs,          // linear blend skinning with the harmonic weights
  kDqs,          // dual quaternion skinning with the harmonic weights
  kCor,  // skinning with optimized centres of rotation (Le & Hodgins 2016): optimized_centers.h
  kDdm,  // Direct Delta Mush (Le & Lewis 2019), full matrices: direct_delta_mush.h
};

// "paper", "paper-linear", "laplacian", "lbs", "dqs", "cor", "ddm".
const char* MethodName(Method method);
// The method MethodName() names; INVALID_ARGUMENT listing the names for any other text.
StatusOr<Method> MethodFromName(std::string_view name);

struct MethodRun {
  Positions posed;  // #V by 3
  QualityReport quality;
  // Model precomputation (weights, regions, symbolic analysis); for cor and ddm plus their own
  // (the centres of rotation, the Omega matrices).
  double precompute_seconds = 0;
  double factor_seconds = 0;       // numeric factorization (0 for skinning)
  std::size_t factor_bytes = 0;    // bytes of the stored factor (0 for skinning)
  std::size_t response_bytes = 0;  // bytes of the linear response (paper-linear only)
  // Medians over `repeat` frames. For paper and laplacian, solve_seconds is the two triangular
  // passes (what the memory-read bound limits) and frame_seconds the whole frame (kinematics,
  // rotation blend, right-hand side, solve); for paper-linear, solve_seconds is evaluating the
  // linear response (or the passes, when the model has none); for the skinning methods both are
  // the whole frame.
  double solve_seconds = 0;
  double frame_seconds = 0;
  int joint_nodes = 0;
  int anchors = 0;
  // With constraints (paper and paper-linear): what they did to the last frame, and the median
  // seconds of applying them (part of frame_seconds).
  ConstraintReport constraints;
  double constraint_seconds = 0;
};

// Builds what `method` needs (the paper's model for its weights, regions and anchors, plus the
// plain Laplacian model for kLaplacian), poses the mesh `repeat` times and measures the result.
// Rigid-zone error is measured on the paper model's anchor vertices for every method.
StatusOr<MethodRun> RunMethod(const TriangleMesh& mesh, const Skeleton& skeleton, Method method,
                              const Pose& pose, int repeat = 1,
                              const ModelOptions& paper_options = ModelOptions::Paper());

// As above, on an already built paper model (the comparison reuses it across methods and poses).
// `constraints` (may be null) were made for `paper_model`: paper and paper-linear frames are
// constrained with them (the default method's frame), and every method's frame is measured
// against their bone surfaces. `tools` (may be null; validated by the caller) go with the
// constraints into paper and paper-linear frames (INVALID_ARGUMENT for other methods, or without
// constraints that take tools).
StatusOr<MethodRun> RunMethod(const DeformationModel& paper_model, Method method, const Pose& pose,
                              int repeat = 1, const SkinConstraints* constraints = nullptr,
                              const ToolSet* tools = nullptr);

}  // namespace deform
