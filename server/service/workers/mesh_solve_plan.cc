#include "service/workers/mesh_solve_plan.h"

namespace deform::service {

MeshSolvePlan PlanMeshSolve(const DeformationModel& model, const SolveSettings& settings) {
  MeshSolvePlan plan;
  // A linear response evaluates each frame alone: nothing to batch or split.
  const MaterialFactorization& factorization = *model.default_factorization();
  if (factorization.linear_response() != nullptr) return plan;
  if (settings.slots >= 2 && factorization.factor().bytes() >= settings.parallel_min_factor_bytes) {
    auto parallel =
        std::make_unique<ParallelSolvePlan>(factorization.factor().PlanParallel(settings.slots));
    if (parallel->parts >= 2) plan.parallel_plan = std::move(parallel);
  }
  if (settings.max_frames >= 2 && settings.slots > 0) {
    plan.batch_scratches = std::make_unique<BatchScratchPool>(
        model, settings.slots, settings.max_frames, plan.parallel_plan.get());
    plan.bytes = BatchScratchPool::Bytes(model, settings.slots, settings.max_frames,
                                         plan.parallel_plan.get());
  }
  return plan;
}

}  // namespace deform::service
