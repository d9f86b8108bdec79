// Per-frame solve, factorization and precomputation of the deformation model on the shared meshes
// (1.6k and 26k leg, 133k arm; skipped where ../shared/data is absent) and the built-in phantom.
//
// Every solve benchmark reports, besides Google Benchmark's mean time:
//   median_ms      the median wall time of one frame (these machines are noisy; compare medians)
//   factor_MB      bytes of the stored factor (values, row indices, column pointers)
//   bound_ms       the memory-read bound: two passes over the factor at the DRAM read bandwidth
//                  (dram_GBps) measured right after the timed frames (a 1 GiB buffer, far larger
//                  than the caches)
//   x_bound        median_ms / bound_ms
//   cache_bound_ms the same two passes at the bandwidth of a factor-sized buffer (cache-resident
//                  where the factor fits the last-level cache), and x_cache_bound
// LinearBlendFrame's bound is one pass over the linear response (response_MB) instead.
// The Eigen baseline solves the same normal equations with Eigen's SimplicialLLT, whose
// multi-column solve walks the factor once per coordinate.
#include <benchmark/benchmark.h>

#include <Eigen/SparseCholesky>
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <map>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "bench/arithmetic_peak.h"
#include "bench/bench_meshes.h"
#include "bench/cholmod_anchor.h"
#include "bench/memory_bandwidth.h"
#include "core/base/build_info.h"
#include "core/base/median.h"
#include "core/constraints/skin_constraints.h"
#include "core/constraints/tool_contact.h"
#include "core/geometry/bone_surface.h"
#include "core/io/model_input.h"
#include "core/io/phantom.h"
#include "core/model/deformation_model.h"

namespace deform::bench {
namespace {

using Clock = std::chrono::steady_clock;

// The wall time of one call of `run`, in seconds.
template <typename Run>
double SecondsOf(Run&& run) {
  const auto start = Clock::now();
  run();
  return std::chrono::duration<double>(Clock::now() - start).count();
}

// Runs `frame` once per benchmark iteration and returns each run's wall time in seconds.
template <typename Frame>
std::vector<double> TimeEach(benchmark::State& state, Frame&& frame) {
  std::vector<double> seconds;
  for (auto _ : state) seconds.push_back(SecondsOf(frame));
  return seconds;
}

// `passes` reads of `bytes` per frame (two over the factor for a solve, one over the linear
// response), reported as `bytes_counter`.
void ReportAgainstBound(benchmark::State& state, std::size_t bytes,
                        const std::vector<double>& seconds, int passes = 2,
                        const char* bytes_counter = "factor_MB") {
  const double median_ms = Median(seconds) * 1e3;
  // Measured again right after the timed frames, so that bound and frames see the same
  // neighbours on a shared machine.
  const double dram_bandwidth = MeasureReadBandwidth(std::size_t{1} << 30, 2);
  const double bound_ms = passes * static_cast<double>(bytes) / dram_bandwidth * 1e3;
  const double cache_bound_ms =
      passes * static_cast<double>(bytes) / MeasureReadBandwidth(bytes, 3) * 1e3;
  state.counters["median_ms"] = median_ms;
  state.counters[bytes_counter] = bytes / 1e6;
  state.counters["bound_ms"] = bound_ms;
  state.counters["x_bound"] = median_ms / bound_ms;
  state.counters["dram_GBps"] = dram_bandwidth / 1e9;
  state.counters["cache_bound_ms"] = cache_bound_ms;
  state.counters["x_cache_bound"] = median_ms / cache_bound_ms;
}

// What the frame benchmarks work on: a mesh's model, its benchmark pose, the model's default
// factorization and a scratch.
struct FrameSetup {
  std::shared_ptr<const DeformationModel> model;
  Pose pose;
  const MaterialFactorization* factorization = nullptr;
  DeformScratch scratch;
};

// The setup for `model` in `mesh`'s benchmark pose, or null with the benchmark skipped when the
// model could not be built.
std::unique_ptr<FrameSetup> SetUpFramesOf(benchmark::State& state, const BenchMesh& mesh,
                                          std::shared_ptr<const DeformationModel> model) {
  if (!model) {
    state.SkipWithError("mesh could not be loaded");
    return nullptr;
  }
  auto setup = std::make_unique<FrameSetup>();
  setup->pose = PoseFromSpecOrRest(*model, mesh.pose_spec);
  setup->factorization = model->default_factorization().get();
  setup->scratch = model->MakeScratch();
  setup->model = std::move(model);
  return setup;
}

// The setup for `mesh` with `blend` (ModelFor).
std::unique_ptr<FrameSetup> SetUpFrames(benchmark::State& state, const BenchMesh& mesh,
                                        RotationBlend blend = RotationBlend::kQuaternion) {
  return SetUpFramesOf(state, mesh, ModelFor(mesh, blend));
}

// The benchmark pose's right-hand side A^T b ((n + m) by 3), a copy that the solves keep as input.
auto AssembledRightHandSide(FrameSetup* frames) {
  frames->model->AssembleRightHandSide(*frames->factorization, frames->pose, &frames->scratch);
  return frames->scratch.solution;
}

// A whole frame: kinematics, rotation blend, right-hand side and both triangular passes.
void BM_Frame(benchmark::State& state, BenchMesh mesh) {
  auto frames = SetUpFrames(state, mesh);
  if (!frames) return;
  const auto seconds = TimeEach(state, [&] {
    frames->model->Deform(*frames->factorization, frames->pose, &frames->scratch);
  });
  ReportAgainstBound(state, frames->factorization->factor().bytes(), seconds);
  state.counters["vertices"] = frames->model->mesh().num_vertices();
}

// A whole frame with the constraints (core/constraints): the frame of BM_Frame, then the skin held
// outside the bones and the volume kept, at `degrees` of flexion (the benchmark pose where 0), on
// the model built for the bones (BonedModelFor). Compare with Frame/ of the same mesh in the same
// run. With `sweep` the frames move, as a stream's do: from degrees - 20 to degrees and back in
// 2-degree steps, a pose a frame, so a frame's contacts are carried from a different pose.
void BM_ConstrainedFrame(benchmark::State& state, BenchMesh mesh, int degrees, bool sweep) {
  const BonedModel boned = BonedModelFor(mesh);
  auto frames = SetUpFramesOf(state, mesh, boned.model);
  if (!frames) return;
  std::vector<Pose> poses;
  if (sweep) {
    for (int d = degrees - 20; d < degrees; d += 2) {
      poses.push_back(PoseFromSpecOrRest(*frames->model, mesh.flexion_prefix + std::to_string(d)));
    }
    for (int d = degrees; d > degrees - 20; d -= 2) {
      poses.push_back(PoseFromSpecOrRest(*frames->model, mesh.flexion_prefix + std::to_string(d)));
    }
  } else if (degrees > 0) {
    poses.push_back(
        PoseFromSpecOrRest(*frames->model, mesh.flexion_prefix + std::to_string(degrees)));
  } else {
    poses.push_back(frames->pose);
  }
  auto bones = BoneContacts::Create(boned.surfaces, frames->model->skeleton(),
                                    frames->model->mesh(), frames->model->rigid_bones());
  if (!bones.ok()) {
    state.SkipWithError(bones.status().ToString().c_str());
    return;
  }
  auto constraints = SkinConstraints::Create(*frames->model, *bones);
  if (!constraints.ok()) {
    state.SkipWithError(constraints.status().ToString().c_str());
    return;
  }
  ConstraintScratch scratch = (*constraints)->MakeScratch();
  ConstraintReport report;
  std::size_t next = 0;
  int most_inside_after = 0;
  double unit_solves = 0, backward_passes = 0, frames_run = 0;
  std::vector<double> apply_seconds;
  const auto seconds = TimeEach(state, [&] {
    frames->model->Deform(*frames->factorization, poses[next], &frames->scratch);
    next = (next + 1) % poses.size();
    apply_seconds.push_back(SecondsOf([&] {
      (*constraints)->Apply(*frames->factorization, &frames->scratch, &scratch, &report);
    }));
    most_inside_after = std::max(most_inside_after, report.after.vertices);
    unit_solves += report.unit_solves;
    backward_passes += report.backward_passes;
    ++frames_run;
  });
  // The same poses' frames without the constraints, on this model: the constraints' own cost
  // is x_unconstrained.
  std::vector<double> unconstrained;
  for (std::size_t f = 0; f < seconds.size(); ++f) {
    unconstrained.push_back(SecondsOf([&] {
      frames->model->Deform(*frames->factorization, poses[f % poses.size()], &frames->scratch);
    }));
  }
  ReportAgainstBound(state, frames->factorization->factor().bytes(), seconds);
  state.counters["unconstrained_ms"] = Median(unconstrained) * 1e3;
  state.counters["x_unconstrained"] = Median(seconds) / Median(unconstrained);
  state.counters["apply_ms"] = Median(apply_seconds) * 1e3;
  // The last frame's, and over every frame the most left inside and the mean passes.
  state.counters["inside_before"] = report.before.vertices;
  state.counters["inside_after_max"] = most_inside_after;
  state.counters["contacts"] = report.contacts;
  state.counters["carried"] = report.carried_contacts;
  state.counters["solves"] = report.solves;
  state.counters["unit_solves_mean"] = unit_solves / std::max(frames_run, 1.0);
  state.counters["backward_passes_mean"] = backward_passes / std::max(frames_run, 1.0);
}

// A whole frame with the constraints and `tool_contacts` tool constraints (0: no tool, the same
// frame as ConstrainedFrame/): four spheres (ToolSet::kMaxTools) pressed half their radius into
// the skin from +x, -x, +z and -z at its extreme vertices in those directions in the middle fifth
// of its height (y, the limbs' long axis) in the benchmark frame, like four fingers, all of one
// radius: the smallest (by bisection) that puts at least `tool_contacts` skin vertices inside them,
// so the frame holds that many (ConstraintOptions::max_tool_contacts); on the model built for the
// bones (BonedModelFor). Compare ToolFrame/tools:0/ with ToolFrame/tools:64/ of the same mesh in
// the same run.
void BM_ToolFrame(benchmark::State& state, BenchMesh mesh, int tool_contacts) {
  const BonedModel boned = BonedModelFor(mesh);
  auto frames = SetUpFramesOf(state, mesh, boned.model);
  if (!frames) return;
  auto bones = BoneContacts::Create(boned.surfaces, frames->model->skeleton(),
                                    frames->model->mesh(), frames->model->rigid_bones());
  if (!bones.ok()) {
    state.SkipWithError(bones.status().ToString().c_str());
    return;
  }
  ConstraintOptions options;
  if (tool_contacts > 0) options.max_tool_contacts = tool_contacts;
  auto constraints = SkinConstraints::Create(*frames->model, *bones, options);
  if (!constraints.ok()) {
    state.SkipWithError(constraints.status().ToString().c_str());
    return;
  }
  ConstraintScratch scratch = (*constraints)->MakeScratch();
  ConstraintReport report;
  frames->model->Deform(*frames->factorization, frames->pose, &frames->scratch);
  (*constraints)->Apply(*frames->factorization, &frames->scratch, &scratch, &report);
  ToolSet tools;
  if (tool_contacts > 0) {
    const Positions free = frames->scratch.positions();
    const double diagonal = frames->model->bounding_box_diagonal();
    const double y_low = free.col(1).minCoeff(), y_high = free.col(1).maxCoeff();
    const Eigen::Vector3d directions[4] = {Eigen::Vector3d::UnitX(), -Eigen::Vector3d::UnitX(),
                                           Eigen::Vector3d::UnitZ(), -Eigen::Vector3d::UnitZ()};
    Eigen::Vector3d extremes[4];
    for (int t = 0; t < 4; ++t) {
      double best = -std::numeric_limits<double>::infinity();
      for (Eigen::Index i = 0; i < free.rows(); ++i) {
        const double h = (free(i, 1) - y_low) / (y_high - y_low);
        const Eigen::Vector3d x = free.row(i).transpose();
        if (h < 0.4 || h > 0.6 || directions[t].dot(x) <= best) continue;
        best = directions[t].dot(x);
        extremes[t] = x;
      }
    }
    const int n = static_cast<int>(free.rows());
    auto press = [&](double radius) {
      tools = {};
      for (int t = 0; t < 4; ++t) {
        Tool tool;
        tool.radius = radius;
        tool.a = extremes[t] + 0.5 * radius * directions[t];
        tools.Add(tool);
      }
      PenetrationSummary summary;
      FindToolPenetrations(tools, free.data(), n, nullptr, 0, &summary);
      return summary.vertices;
    };
    double low = 0, high = 0.25 * diagonal;
    for (int step = 0; step < 40; ++step) {
      const double middle = 0.5 * (low + high);
      (press(middle) >= tool_contacts ? high : low) = middle;
    }
    press(high);
    state.counters["tool_radius_per_diagonal"] = high / diagonal;
  }
  const auto seconds = TimeEach(state, [&] {
    frames->model->Deform(*frames->factorization, frames->pose, &frames->scratch);
    (*constraints)
        ->Apply(*frames->factorization, &frames->scratch, &scratch, &report,
                tools.empty() ? nullptr : &tools);
  });
  ReportAgainstBound(state, frames->factorization->factor().bytes(), seconds);
  state.counters["tool_contacts"] = report.tool_contacts;
  state.counters["tool_inside_before"] = report.tool_before.vertices;
  state.counters["tool_inside_after"] = report.tool_after.vertices;
  state.counters["rounds"] = report.rounds;
}

// A whole frame of the linear rotation blend (METHOD.md's fast path): kinematics and one pass over
// the precomputed response, no solve. Compare with Frame/ of the same mesh in the same run.
void BM_LinearBlendFrame(benchmark::State& state, BenchMesh mesh) {
  auto frames = SetUpFrames(state, mesh, RotationBlend::kLinear);
  if (!frames) return;
  const LinearPoseResponse* response = frames->factorization->linear_response();
  if (response == nullptr) return state.SkipWithError("no linear response (larger than factor)");
  const auto seconds = TimeEach(state, [&] {
    frames->model->Deform(*frames->factorization, frames->pose, &frames->scratch);
  });
  ReportAgainstBound(state, response->bytes(), seconds, 1, "response_MB");
}

// The two triangular passes alone (what the memory-read bound limits), with the given kernel.
void BM_TriangularSolve(benchmark::State& state, BenchMesh mesh, SolveKernel kernel) {
  if (!SolveKernelAvailable(kernel)) return state.SkipWithError("kernel not available here");
  auto frames = SetUpFrames(state, mesh);
  if (!frames) return;
  const CholeskyFactor& factor = frames->factorization->factor();
  DeformScratch& scratch = frames->scratch;
  const auto rhs = AssembledRightHandSide(frames.get());
  const auto seconds = TimeEach(state, [&] {
    benchmark::DoNotOptimize(
        factor.Solve3(rhs.data(), scratch.solution.data(), scratch.solve_work.data(), kernel));
  });
  ReportAgainstBound(state, factor.bytes(), seconds);
}

// `run` timed max(runs, 20) times after another benchmark's timed loop, for the comparisons made
// in one benchmark (each run's wall time in seconds).
template <typename Run>
std::vector<double> TimeRuns(std::size_t runs, Run&& run) {
  std::vector<double> seconds;
  for (std::size_t i = 0; i < std::max<std::size_t>(runs, 20); ++i) {
    seconds.push_back(SecondsOf(run));
  }
  return seconds;
}

// Solve3 on `rhs`, timed as TimeRuns does.
template <typename Rhs>
std::vector<double> TimeSolve3(const CholeskyFactor& factor, const Rhs& rhs, DeformScratch* scratch,
                               std::size_t runs) {
  return TimeRuns(runs, [&] {
    benchmark::DoNotOptimize(
        factor.Solve3(rhs.data(), scratch->solution.data(), scratch->solve_work.data()));
  });
}

// `count` copies of a right-hand side, each in an array of its own as DeformBatch solves them
// (in place), with the input and output pointers SolveFrames takes.
struct FramesInArrays {
  template <typename Rhs>
  FramesInArrays(const Rhs& rhs, int count)
      : solved(count, std::vector<double>(rhs.data(), rhs.data() + rhs.size())),
        in(count, rhs.data()) {
    for (std::vector<double>& frame : solved) out.push_back(frame.data());
  }
  std::vector<std::vector<double>> solved;
  std::vector<const double*> in;
  std::vector<double*> out;
};

// Writes one double per cache line of a buffer far larger than any cache (256 MiB), so that what
// a frame reads next comes from memory.
void EvictCaches() {
  static std::vector<double> buffer(std::size_t{32} << 20, 1.0);
  for (std::size_t i = 0; i < buffer.size(); i += 8) buffer[i] += 1.0;
  benchmark::DoNotOptimize(buffer.data());
}

// TimeEach with the caches emptied (EvictCaches, untimed) before each run.
template <typename Frame>
std::vector<double> TimeEachCold(benchmark::State& state, Frame&& frame) {
  std::vector<double> seconds;
  for (auto _ : state) {
    state.PauseTiming();
    EvictCaches();
    state.ResumeTiming();
    seconds.push_back(SecondsOf(frame));
  }
  return seconds;
}

// The two triangular passes of a lone frame (frames 1: Solve3) or of a batch (SolveFrames) with
// the caches emptied before each run: what a solve costs when the factor, the right-hand sides
// and the solution rows come from memory, as in a service whose frames are far apart or whose
// other work (and a shared machine's neighbours) evicts them between solves. With `float32`, the
// factor rounded to float32 (RoundedToFloat32). Besides the usual counters (the bounds those of
// the factor solved): hot_ms, the same solve's median back to back (cache-resident where the
// factor fits) timed in the same benchmark, and x_hot, their ratio.
void BM_ColdSolve(benchmark::State& state, BenchMesh mesh, int frames_per_batch, bool float32) {
  auto frames = SetUpFrames(state, mesh);
  if (!frames) return;
  const CholeskyFactor& exact = frames->factorization->factor();
  const CholeskyFactor rounded = float32 ? exact.RoundedToFloat32() : CholeskyFactor();
  const CholeskyFactor& factor = float32 ? rounded : exact;
  DeformScratch& scratch = frames->scratch;
  const auto rhs = AssembledRightHandSide(frames.get());
  FramesInArrays batch(rhs, frames_per_batch);
  std::vector<double> batch_work(factor.WorkSizeMany(3 * frames_per_batch));
  const auto solve = [&] {
    if (frames_per_batch == 1) {
      benchmark::DoNotOptimize(
          factor.Solve3(rhs.data(), scratch.solution.data(), scratch.solve_work.data()));
    } else {
      benchmark::DoNotOptimize(factor.SolveFrames(batch.in.data(), batch.out.data(),
                                                  frames_per_batch, batch_work.data()));
    }
  };
  const auto seconds = TimeEachCold(state, solve);
  const std::vector<double> hot = TimeRuns(seconds.size(), solve);
  ReportAgainstBound(state, factor.bytes(), seconds);
  state.counters["frames"] = frames_per_batch;
  state.counters["hot_ms"] = Median(hot) * 1e3;
  state.counters["x_hot"] = Median(seconds) / Median(hot);
}

// `frames` frames' two triangular passes in one batch with `kernel` (CholeskyFactor::SolveFrames,
// as DeformBatch runs them: each frame's right-hand side and solution in arrays of their own), the
// right-hand sides those of the benchmark pose. Besides the counters of the other solves
// (median_ms and the bounds are per batch): frame_ms, the median per frame; unbatched_frame_ms,
// Solve3's median (the best kernel) on the same right-hand side timed in the same benchmark;
// x_unbatched, their ratio; frame_bound_ms and frame_cache_bound_ms, the bounds per frame; and
// the arithmetic bound, which a batch of several frames meets before the bytes' (each value read
// serves every column): arith_bound_ms, both passes' multiply-adds of L's non-zeros (the
// kernel's explicit zeros not counted) into the batch's columns padded to the kernel's vectors
// (three frames' nine columns are twelve with four-double vectors) at this core's rate in the
// kernel's instructions, measured right after (madd_G_per_s: MeasureMultiplyAddRate), and
// x_arith_bound = median_ms / arith_bound_ms.
void BM_BatchedSolve(benchmark::State& state, BenchMesh mesh, int frames_per_batch,
                     SolveKernel kernel) {
  if (!SolveKernelAvailable(kernel)) return state.SkipWithError("kernel not available here");
  auto frames = SetUpFrames(state, mesh);
  if (!frames) return;
  const CholeskyFactor& factor = frames->factorization->factor();
  DeformScratch& scratch = frames->scratch;
  const auto rhs = AssembledRightHandSide(frames.get());
  FramesInArrays batch(rhs, frames_per_batch);
  std::vector<double> work(factor.WorkSizeMany(3 * frames_per_batch));
  const auto seconds = TimeEach(state, [&] {
    benchmark::DoNotOptimize(factor.SolveFrames(batch.in.data(), batch.out.data(), frames_per_batch,
                                                work.data(), kernel));
  });
  const std::vector<double> unbatched = TimeSolve3(factor, rhs, &scratch, seconds.size());
  ReportAgainstBound(state, factor.bytes(), seconds);
  const double frame_ms = Median(seconds) * 1e3 / frames_per_batch;
  state.counters["frames"] = frames_per_batch;
  state.counters["frame_ms"] = frame_ms;
  state.counters["unbatched_frame_ms"] = Median(unbatched) * 1e3;
  state.counters["x_unbatched"] = frame_ms / (Median(unbatched) * 1e3);
  state.counters["frame_bound_ms"] = state.counters["bound_ms"] / frames_per_batch;
  state.counters["frame_cache_bound_ms"] = state.counters["cache_bound_ms"] / frames_per_batch;
  const int lanes = SolveKernelFunctionsFor(kernel).batch_lanes;
  const int padded_columns = BatchRowStride(lanes, 3 * frames_per_batch);
  const double multiply_add_rate = MeasureMultiplyAddRate(kernel);
  const double arith_bound_ms =
      2.0 * static_cast<double>(factor.nonzeros()) * padded_columns / multiply_add_rate * 1e3;
  state.counters["madd_G_per_s"] = multiply_add_rate / 1e9;
  state.counters["arith_bound_ms"] = arith_bound_ms;
  state.counters["x_arith_bound"] = Median(seconds) * 1e3 / arith_bound_ms;
}

// One frame's two triangular passes split over `parts` threads (CholeskyFactor::Solve3Parallel on a
// ThreadTeam of `parts` threads). Besides the usual counters: serial_ms, Solve3's median on the
// same right-hand side timed in the same benchmark; x_serial, their ratio; top_share, the share of
// the factor solved on one thread; predicted_x_serial, the ratio if time followed the bytes read.
void BM_ParallelSolve(benchmark::State& state, BenchMesh mesh, int parts) {
  auto frames = SetUpFrames(state, mesh);
  if (!frames) return;
  const CholeskyFactor& factor = frames->factorization->factor();
  DeformScratch& scratch = frames->scratch;
  const auto rhs = AssembledRightHandSide(frames.get());
  const ParallelSolvePlan plan = factor.PlanParallel(parts);
  if (plan.parts == 0) return state.SkipWithError("the elimination tree does not split");
  std::vector<double> work(factor.WorkSizeParallel(plan));
  ThreadTeam team(parts);
  const auto seconds = TimeEach(state, [&] {
    benchmark::DoNotOptimize(
        factor.Solve3Parallel(plan, rhs.data(), scratch.solution.data(), work.data(), &team));
  });
  const Eigen::MatrixXd parallel_result = scratch.solution;  // (the last timed run's)
  const std::vector<double> serial = TimeSolve3(factor, rhs, &scratch, seconds.size());
  ReportAgainstBound(state, factor.bytes(), seconds);
  // The parallel solve's difference from Solve3's, relative to the solution's norm.
  state.counters["relative_difference"] =
      (parallel_result - scratch.solution).norm() / scratch.solution.norm();
  state.counters["serial_ms"] = Median(serial) * 1e3;
  state.counters["x_serial"] = Median(seconds) / Median(serial);
  state.counters["top_share"] = plan.top_share;
  state.counters["predicted_x_serial"] = plan.predicted_time_ratio;
}

// A batch of `frames_per_batch` frames' two triangular passes split over `parts` threads
// (CholeskyFactor::SolveFramesParallel on a ThreadTeam of `parts` threads), the right-hand sides
// those of the benchmark pose. Besides the usual counters (per batch): frame_ms, the median per
// frame; serial_batch_ms, the same batch's SolveFrames on one thread timed in the same benchmark;
// x_serial, their ratio; relative_difference, the largest frame's difference from Solve3's.
void BM_ParallelBatchedSolve(benchmark::State& state, BenchMesh mesh, int frames_per_batch,
                             int parts) {
  auto frames = SetUpFrames(state, mesh);
  if (!frames) return;
  const CholeskyFactor& factor = frames->factorization->factor();
  DeformScratch& scratch = frames->scratch;
  const auto rhs = AssembledRightHandSide(frames.get());
  const ParallelSolvePlan plan = factor.PlanParallel(parts);
  if (plan.parts == 0) return state.SkipWithError("the elimination tree does not split");
  FramesInArrays batch(rhs, frames_per_batch);
  std::vector<double> work(factor.WorkSizeFramesParallel(plan, frames_per_batch));
  ThreadTeam team(parts);
  const auto seconds = TimeEach(state, [&] {
    benchmark::DoNotOptimize(factor.SolveFramesParallel(plan, batch.in.data(), batch.out.data(),
                                                        frames_per_batch, work.data(), &team));
  });
  const std::vector<std::vector<double>> parallel_result = batch.solved;  // (the last timed run's)
  std::vector<double> serial_work(factor.WorkSizeMany(3 * frames_per_batch));
  const std::vector<double> serial = TimeRuns(seconds.size(), [&] {
    benchmark::DoNotOptimize(factor.SolveFrames(batch.in.data(), batch.out.data(), frames_per_batch,
                                                serial_work.data()));
  });
  (void)factor.Solve3(rhs.data(), scratch.solution.data(), scratch.solve_work.data());
  double difference = 0;
  for (const std::vector<double>& frame : parallel_result) {
    const Eigen::Map<const Eigen::VectorXd> x(frame.data(), scratch.solution.size());
    const Eigen::Map<const Eigen::VectorXd> expected(scratch.solution.data(),
                                                     scratch.solution.size());
    difference = std::max(difference, (x - expected).norm() / expected.norm());
  }
  ReportAgainstBound(state, factor.bytes(), seconds);
  state.counters["frames"] = frames_per_batch;
  state.counters["frame_ms"] = Median(seconds) * 1e3 / frames_per_batch;
  state.counters["serial_batch_ms"] = Median(serial) * 1e3;
  state.counters["x_serial"] = Median(seconds) / Median(serial);
  state.counters["relative_difference"] = difference;
}

// The two triangular passes with the factor's values rounded to float32 (CholeskyFactor::
// RoundedToFloat32; the arithmetic stays double), on one thread (parts 1, Solve3) or split over
// `parts` threads (Solve3Parallel), against the double factor's same solve timed in the same
// benchmark. Besides the usual counters (factor_MB and the bounds those of the float32 factor):
// double_ms, the double solve's median; x_double, their ratio; max_difference, the largest vertex
// difference between the two solutions relative to the bounding-box diagonal.
void BM_Float32Solve(benchmark::State& state, BenchMesh mesh, int parts) {
  auto frames = SetUpFrames(state, mesh);
  if (!frames) return;
  const CholeskyFactor& exact = frames->factorization->factor();
  const CholeskyFactor rounded = exact.RoundedToFloat32();
  DeformScratch& scratch = frames->scratch;
  const auto rhs = AssembledRightHandSide(frames.get());
  const ParallelSolvePlan plan = exact.PlanParallel(parts);
  if (parts > 1 && plan.parts == 0)
    return state.SkipWithError("the elimination tree does not split");
  std::vector<double> work(parts > 1 ? exact.WorkSizeParallel(plan) : exact.WorkSize());
  ThreadTeam team(parts);
  const auto solve = [&](const CholeskyFactor& factor) {
    return parts > 1 ? factor.Solve3Parallel(plan, rhs.data(), scratch.solution.data(), work.data(),
                                             &team)
                     : factor.Solve3(rhs.data(), scratch.solution.data(), work.data());
  };
  const auto seconds = TimeEach(state, [&] { benchmark::DoNotOptimize(solve(rounded)); });
  const auto rounded_solution = scratch.solution;
  const std::vector<double> exact_seconds =
      TimeRuns(seconds.size(), [&] { benchmark::DoNotOptimize(solve(exact)); });
  ReportAgainstBound(state, rounded.bytes(), seconds);
  const int n = frames->model->mesh().num_vertices();
  state.counters["max_difference"] =
      (rounded_solution.topRows(n) - scratch.solution.topRows(n)).rowwise().norm().maxCoeff() /
      frames->model->bounding_box_diagonal();
  state.counters["double_ms"] = Median(exact_seconds) * 1e3;
  state.counters["x_double"] = Median(seconds) / Median(exact_seconds);
}

// The right-hand side alone: kinematics, rotation blend and the product with L'^T.
void BM_RightHandSide(benchmark::State& state, BenchMesh mesh) {
  auto frames = SetUpFrames(state, mesh);
  if (!frames) return;
  const auto seconds = TimeEach(state, [&] {
    frames->model->AssembleRightHandSide(*frames->factorization, frames->pose, &frames->scratch);
  });
  state.counters["median_ms"] = Median(seconds) * 1e3;
}

// A batch's right-hand sides as DeformBatch assembles them (kinematics and rotation blend of each
// frame, the general rows of all frames in one pass, each frame's rigid rows and targets): the
// median of DeformBatch's right_hand_side timing, per frame (rhs_frame_ms), against the same
// frames deformed one at a time by Deform in the same benchmark, its right_hand_side timing
// (unbatched_rhs_frame_ms), and their ratio (x_unbatched). Both follow a solve, as in the service.
void BM_BatchedRightHandSide(benchmark::State& state, BenchMesh mesh, int frames_per_batch) {
  auto frames = SetUpFrames(state, mesh);
  if (!frames) return;
  const DeformationModel& model = *frames->model;
  std::vector<DeformScratch> scratches;
  for (int f = 0; f < frames_per_batch; ++f) scratches.push_back(model.MakeScratch());
  std::vector<DeformScratch*> scratch_pointers;
  std::vector<const Pose*> poses(frames_per_batch, &frames->pose);
  for (DeformScratch& scratch : scratches) scratch_pointers.push_back(&scratch);
  DeformBatchScratch batch = model.MakeBatchScratch(frames_per_batch);
  std::vector<double> right_hand_sides, unbatched;
  for (auto _ : state) {
    DeformTimings timings;
    model.DeformBatch(*frames->factorization, poses.data(), scratch_pointers.data(),
                      frames_per_batch, &batch, &timings);
    right_hand_sides.push_back(timings.right_hand_side / frames_per_batch);
    for (DeformScratch* scratch : scratch_pointers) {
      model.Deform(*frames->factorization, frames->pose, scratch, &timings);
      unbatched.push_back(timings.right_hand_side);
    }
  }
  state.counters["frames"] = frames_per_batch;
  state.counters["rhs_frame_ms"] = Median(right_hand_sides) * 1e3;
  state.counters["unbatched_rhs_frame_ms"] = Median(unbatched) * 1e3;
  state.counters["x_unbatched"] = Median(right_hand_sides) / Median(unbatched);
}

// Baseline: Eigen's SimplicialLLT (AMD ordering) on the same system, three columns at once.
void BM_EigenBaselineSolve(benchmark::State& state, BenchMesh mesh) {
  auto frames = SetUpFrames(state, mesh);
  if (!frames) return;
  Eigen::SimplicialLLT<Eigen::SparseMatrix<double>> llt(
      frames->model->NormalMatrix(*frames->factorization));
  frames->model->AssembleRightHandSide(*frames->factorization, frames->pose, &frames->scratch);
  const Eigen::MatrixXd rhs = frames->scratch.solution;
  Eigen::MatrixXd x(rhs.rows(), 3);
  const auto seconds = TimeEach(state, [&] {
    x = llt.solve(rhs);
    benchmark::DoNotOptimize(x.data());
  });
  const auto& l = llt.matrixL().nestedExpression();
  ReportAgainstBound(
      state, l.nonZeros() * (sizeof(double) + sizeof(int)) + (l.cols() + 1) * sizeof(int), seconds);
}

// A numeric refactorization (as after a stiffness change), reusing the symbolic analysis.
void BM_Factorize(benchmark::State& state, BenchMesh mesh) {
  auto model = ModelFor(mesh);
  if (!model) return state.SkipWithError("mesh could not be loaded");
  std::vector<double> seconds;
  Stiffness stiffness;
  for (auto _ : state) {
    const auto start = Clock::now();
    auto f = model->Factorize(stiffness);
    benchmark::DoNotOptimize(f);
    seconds.push_back(std::chrono::duration<double>(Clock::now() - start).count());
  }  // the factor is freed outside the timed span
  state.counters["median_ms"] = Median(seconds) * 1e3;
  state.counters["factor_MB"] = model->default_factorization()->factor().bytes() / 1e6;
}

// The numeric factorization alone on `threads` threads (a ThreadTeam for two), of the model's
// normal matrix with the model's ordering, and CHOLMOD's (cholmod_anchor.h) of the same matrix with
// the same permutation on as many BLAS threads, the two alternating: x_cholmod = ours / CHOLMOD's
// (medians). Without CHOLMOD in the build, ours alone.
void BM_NumericFactorization(benchmark::State& state, BenchMesh mesh, int threads) {
  auto model = ModelFor(mesh);
  if (!model) return state.SkipWithError("mesh could not be loaded");
  Eigen::SparseMatrix<double> a = model->NormalMatrix(*model->default_factorization());
  a.makeCompressed();
  auto symbolic = SymbolicCholesky::Analyze(a, model->options().ordering);
  if (!symbolic.ok()) return state.SkipWithError(symbolic.status().ToString().c_str());
  std::unique_ptr<ThreadTeam> team = threads > 1 ? std::make_unique<ThreadTeam>(threads) : nullptr;
  std::unique_ptr<CholmodAnchor> cholmod = CholmodAnchor::Create(a, (*symbolic)->permutation());
  std::vector<double> seconds, cholmod_seconds;
  for (auto _ : state) {
    const auto start = Clock::now();
    auto factor = CholeskyFactor::Factorize(*symbolic, a, nullptr, team.get());
    seconds.push_back(std::chrono::duration<double>(Clock::now() - start).count());
    if (!factor.ok()) return state.SkipWithError(factor.status().ToString().c_str());
    if (cholmod) {
      state.PauseTiming();
      const double s = cholmod->Factorize(threads);
      if (s >= 0) cholmod_seconds.push_back(s);
      state.ResumeTiming();
    }
  }
  state.counters["median_ms"] = Median(seconds) * 1e3;
  state.counters["vertices"] = model->mesh().num_vertices();
  state.counters["L_nonzeros_M"] = static_cast<double>((*symbolic)->factor_nonzeros()) / 1e6;
  if (!cholmod_seconds.empty()) {
    state.counters["cholmod_ms"] = Median(cholmod_seconds) * 1e3;
    state.counters["x_cholmod"] = Median(seconds) / Median(cholmod_seconds);
    state.counters["cholmod_blas_threads"] = cholmod->blas_threads();
    state.counters["cholmod_supernodal"] = cholmod->supernodal() ? 1 : 0;
    state.counters["cholmod_L_nonzeros_M"] = cholmod->factor_nonzeros() / 1e6;
  }
}

// Everything Build() does: validation, weights, regions, symbolic analysis, first factorization.
void BM_Precompute(benchmark::State& state, BenchMesh mesh) {
  auto input = LoadModelInput(mesh.mesh_path, mesh.skeleton_path, mesh.phantom_vertices);
  if (!input.ok()) return state.SkipWithError(input.status().ToString().c_str());
  std::vector<double> seconds, precompute;
  for (auto _ : state) {
    const auto start = Clock::now();
    auto model = DeformationModel::Build(input->mesh, input->skeleton, ModelOptions::Paper());
    seconds.push_back(std::chrono::duration<double>(Clock::now() - start).count());
    if (model.ok()) precompute.push_back((*model)->precompute_seconds());
  }  // the model is freed outside the timed span
  state.counters["median_ms"] = Median(seconds) * 1e3;
  state.counters["precompute_ms"] = Median(precompute) * 1e3;  // before the first factorization
}

// The contact query of QueryContact (core/constraints/tool_contact.h) on the benchmark pose's
// skin: the tree built at rest and refitted to the posed skin once, then spheres of 1% of the
// diagonal centred within 1% of the diagonal of the posed vertices (in contact or near it, as a
// haptic tool is), 256 per iteration. median_us: one query.
void BM_ContactQuery(benchmark::State& state, BenchMesh mesh) {
  auto frames = SetUpFrames(state, mesh);
  if (!frames) return;
  const DeformationModel& model = *frames->model;
  model.Deform(*frames->factorization, frames->pose, &frames->scratch);
  const Positions posed = frames->scratch.positions();
  auto query = SkinContactQuery::Create(model.mesh(), {});
  if (!query.ok()) {
    state.SkipWithError(query.status().ToString().c_str());
    return;
  }
  (*query)->Refit(posed.data());
  const double diagonal = model.bounding_box_diagonal();
  constexpr int kQueries = 256;
  std::vector<Tool> tools(kQueries);
  std::mt19937 random(1);
  std::uniform_int_distribution<int> vertex(0, model.mesh().num_vertices() - 1);
  std::uniform_real_distribution<double> offset(-0.01 * diagonal, 0.01 * diagonal);
  for (Tool& tool : tools) {
    tool.radius = 0.01 * diagonal;
    tool.a = posed.row(vertex(random)).transpose() +
             Eigen::Vector3d(offset(random), offset(random), offset(random));
    tool.b = tool.a;
  }
  double depth = 0;
  const auto seconds = TimeEach(state, [&] {
    for (const Tool& tool : tools) depth += (*query)->Query(tool, {}).depth;
  });
  benchmark::DoNotOptimize(depth);
  state.counters["median_us"] = Median(seconds) / kQueries * 1e6;
  state.counters["triangles"] = model.mesh().num_triangles();
}

// The refit of the contact query's tree (SkinContactQuery::Refit) to the benchmark pose's skin:
// what a query pays once after each newer frame.
void BM_ContactRefit(benchmark::State& state, BenchMesh mesh) {
  auto frames = SetUpFrames(state, mesh);
  if (!frames) return;
  const DeformationModel& model = *frames->model;
  model.Deform(*frames->factorization, frames->pose, &frames->scratch);
  const Positions posed = frames->scratch.positions();
  auto query = SkinContactQuery::Create(model.mesh(), {});
  if (!query.ok()) {
    state.SkipWithError(query.status().ToString().c_str());
    return;
  }
  const auto seconds = TimeEach(state, [&] { (*query)->Refit(posed.data()); });
  state.counters["median_ms"] = Median(seconds) * 1e3;
  state.counters["triangles"] = model.mesh().num_triangles();
}

// Registers benchmark `name`/<mesh> of `function`(state, mesh, extra...), timed in milliseconds.
template <typename Function, typename... Extra>
benchmark::internal::Benchmark* RegisterFor(const BenchMesh& mesh, const std::string& name,
                                            Function function, Extra... extra) {
  return benchmark::RegisterBenchmark((name + "/" + mesh.name).c_str(), function, mesh, extra...)
      ->Unit(benchmark::kMillisecond);
}

// The numeric factorization on one thread and on two, fewer times on the large meshes.
void RegisterNumericFactorization(const BenchMesh& mesh) {
  const bool large = mesh.name == "arm_132946" || mesh.phantom_vertices >= 100'000;
  for (const int threads : {1, 2}) {
    RegisterFor(mesh, "NumericFactorization/threads:" + std::to_string(threads),
                BM_NumericFactorization, threads)
        ->Iterations(large ? 3 : 7);
  }
}

// Every benchmark of one mesh (the 133k arm with fewer precomputation iterations).
void RegisterBenchmarks(const BenchMesh& mesh) {
  const bool large = mesh.name == "arm_132946";
  RegisterFor(mesh, "Precompute", BM_Precompute)->Iterations(large ? 1 : 3);
  RegisterFor(mesh, "Factorize", BM_Factorize)->Iterations(large ? 2 : 5);
  RegisterNumericFactorization(mesh);
  RegisterFor(mesh, "Frame", BM_Frame)->MinTime(1.0);
  RegisterFor(mesh, "ConstrainedFrame", BM_ConstrainedFrame, 0, false)->MinTime(1.0);
  RegisterFor(mesh, "ConstrainedFrame/degrees:120", BM_ConstrainedFrame, 120, false)->MinTime(1.0);
  RegisterFor(mesh, "ConstrainedFrame/sweep:100-120", BM_ConstrainedFrame, 120, true)->MinTime(1.0);
  for (const int tool_contacts : {0, 64}) {
    RegisterFor(mesh, "ToolFrame/tools:" + std::to_string(tool_contacts), BM_ToolFrame,
                tool_contacts)
        ->MinTime(1.0);
  }
  RegisterFor(mesh, "ContactQuery", BM_ContactQuery)->MinTime(0.5);
  RegisterFor(mesh, "ContactRefit", BM_ContactRefit)->MinTime(0.5);
  RegisterFor(mesh, "LinearBlendFrame", BM_LinearBlendFrame)->MinTime(1.0);
  RegisterFor(mesh, "RightHandSide", BM_RightHandSide)->MinTime(0.5);
  RegisterFor(mesh, "TriangularSolve", BM_TriangularSolve, BestSolveKernel())->MinTime(1.0);
  for (const int frames : {1, 8}) {
    for (const bool float32 : {false, true}) {
      RegisterFor(mesh,
                  std::string(float32 ? "ColdFloat32Solve" : "ColdSolve") +
                      "/frames:" + std::to_string(frames),
                  BM_ColdSolve, frames, float32)
          ->MinTime(1.0);
    }
  }
  if (BestSolveKernel() != SolveKernel::kBaseline) {
    RegisterFor(mesh, "TriangularSolveBaselineKernel", BM_TriangularSolve, SolveKernel::kBaseline)
        ->MinTime(1.0);
  }
  for (const int frames : {1, 2, 4, 8, 16}) {
    RegisterFor(mesh, "BatchedSolve/frames:" + std::to_string(frames), BM_BatchedSolve, frames,
                BestSolveKernel())
        ->MinTime(1.0);
  }
  if (BestSolveKernel() == SolveKernel::kAvx512) {  // the four-wide batch in the same run
    RegisterFor(mesh, "BatchedSolveAvx2Kernel/frames:8", BM_BatchedSolve, 8, SolveKernel::kAvx2Fma)
        ->MinTime(1.0);
  }
  for (const int frames : {8, 16}) {
    RegisterFor(mesh, "BatchedRightHandSide/frames:" + std::to_string(frames),
                BM_BatchedRightHandSide, frames)
        ->MinTime(1.0);
  }
  RegisterFor(mesh, "ParallelSolve/parts:2", BM_ParallelSolve, 2)->MinTime(1.0);
  for (const int frames : {4, 8}) {
    RegisterFor(mesh, "ParallelBatchedSolve/frames:" + std::to_string(frames) + "/parts:2",
                BM_ParallelBatchedSolve, frames, 2)
        ->MinTime(1.0);
  }
  RegisterFor(mesh, "Float32Solve/parts:1", BM_Float32Solve, 1)->MinTime(1.0);
  RegisterFor(mesh, "Float32Solve/parts:2", BM_Float32Solve, 2)->MinTime(1.0);
  RegisterFor(mesh, "EigenBaselineSolve", BM_EigenBaselineSolve)->MinTime(1.0);
}

}  // namespace
}  // namespace deform::bench

int main(int argc, char** argv) {
  using namespace deform::bench;
  if (deform::PrintVersionIfAsked(argc, argv, "deform_bench")) return 0;
  benchmark::Initialize(&argc, argv);
  benchmark::AddCustomContext("build", deform::VersionLine("deform_bench"));
  benchmark::AddCustomContext("dram_read_GBps_at_start",
                              std::to_string(MeasureReadBandwidth(std::size_t{1} << 30) / 1e9));
  benchmark::AddCustomContext("solve_kernel", deform::SolveKernelName(deform::BestSolveKernel()));
  for (const BenchMesh& mesh : AvailableMeshes()) RegisterBenchmarks(mesh);
  for (const BenchMesh& mesh : FactorizationScalingMeshes()) RegisterNumericFactorization(mesh);
  benchmark::AddCustomContext("cholmod", CholmodAnchor::Available() ? "linked" : "absent");
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
