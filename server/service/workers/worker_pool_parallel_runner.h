// A ParallelRunner (core/solver/parallel_solve.h) on the service's worker pool: the parts of one
// computation (a big mesh's frame or batch: right-hand sides and solve) are taken by the calling
// worker and by helper tasks posted for the other workers, busy or not: an idle worker takes parts
// at once, a busy one once it frees up while parts are left (a batch's solve outlasts the other
// worker's task more often than not), and a helper that starts after the last part finds nothing
// and returns. With no other worker free the caller runs every part itself and does not wait.
//
// One runner per stream (its helpers are its own tasks, posted at most once at a time, allocated
// with the runner). Run is called by one thread at a time (the stream's solve task) and allocates
// nothing; it returns once every part has run. The pool must outlive the runner's posted helpers
// (the pool keeps them alive until they have run).
#pragma once

#include <memory>
#include <vector>

#include "core/solver/parallel_solve.h"
#include "service/workers/worker_pool.h"

namespace deform::service {

class WorkerPoolParallelRunner final : public ParallelRunner {
 public:
  explicit WorkerPoolParallelRunner(WorkerPool* pool);
  ~WorkerPoolParallelRunner();
  WorkerPoolParallelRunner(const WorkerPoolParallelRunner&) = delete;
  WorkerPoolParallelRunner& operator=(const WorkerPoolParallelRunner&) = delete;

  void Run(int count, void (*part)(void* context, int index), void* context) override;
  // The pool's idle workers, at most this runner's helpers.
  int IdleHelpers() override;

 private:
  struct Job;
  class Helper;

  WorkerPool* const pool_;
  std::shared_ptr<Job> job_;                      // shared with the helpers
  std::vector<std::shared_ptr<Helper>> helpers_;  // pool size - 1
};

}  // namespace deform::service
