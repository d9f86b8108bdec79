// The service as the stream and HTTP fuzz targets drive it: one ServiceContext per process (one
// worker, so that WaitForWorkers can tell when every task a call posted has run), the knee phantom
// loaded through the LoadMesh path's own builder, and the service's log lines formatted and
// escaped as deformd's but written nowhere.
#pragma once

#include <google/protobuf/stubs/logging.h>
#include <spdlog/sinks/null_sink.h>
#include <spdlog/spdlog.h>

#include <chrono>
#include <condition_variable>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <mutex>
#include <string>

#include "deform/v1/deform.pb.h"
#include "service/base/log_text.h"
#include "service/context/service_context.h"
#include "service/load/load_request.h"
#include "service/load/mesh_loader.h"

namespace deform::fuzz {

[[noreturn]] inline void SetupFailed(const std::string& what) {
  std::fprintf(stderr, "fuzz setup failed: %s\n", what.c_str());
  std::abort();
}

// A check of the target's own (not the transport contract's) failed.
[[noreturn]] inline void CheckFailed(const char* what) {
  std::fprintf(stderr, "fuzz check failed: %s\n", what);
  std::abort();
}

// The default and audit loggers as EscapingLoggers over a null sink (before the first context).
inline void DiscardServiceLogs() {
  auto sink = std::make_shared<spdlog::sinks::null_sink_mt>();
  auto logger = std::make_shared<service::EscapingLogger>("deformd", spdlog::sinks_init_list{sink});
  logger->set_level(spdlog::level::info);
  spdlog::set_default_logger(logger);
  auto audit = std::make_shared<service::EscapingLogger>("audit", spdlog::sinks_init_list{sink});
  audit->set_level(spdlog::level::info);
  spdlog::register_logger(audit);
}

// A context with one worker and `limits`, for the whole process. Protobuf's own log lines (invalid
// UTF-8 in a string field the fuzzer wrote) are dropped too.
inline std::unique_ptr<service::ServiceContext> NewFuzzContext(
    const service::ServiceLimits& limits) {
  DiscardServiceLogs();
  google::protobuf::SetLogHandler(nullptr);
  service::ServerOptions options;
  options.workers = 1;
  options.limits = limits;
  return std::make_unique<service::ServiceContext>(options);
}

// Loads a knee phantom of `vertices` (with its bones unless `without_bones`) for the implicit
// tenant, under `id` if not empty, as a LoadMesh with a phantom header would.
inline std::shared_ptr<const service::MeshEntry> LoadPhantom(service::ServiceContext* context,
                                                             int vertices, bool without_bones,
                                                             const std::string& id = "") {
  v1::LoadMeshHeader header;
  header.mutable_phantom()->set_vertices(vertices);
  header.mutable_phantom()->set_without_bones(without_bones);
  std::string no_bytes;
  auto job = service::LoadJobFromRequest(header, &no_bytes, context->limits());
  if (!job.ok()) SetupFailed(job.status().ToString());
  job->id = id;
  auto slot = context->admission().ReserveMesh();
  if (!slot.ok()) SetupFailed(slot.status().ToString());
  auto entry = service::BuildAndRegister(context, std::move(*slot), std::move(*job));
  if (!entry.ok()) SetupFailed(entry.status().ToString());
  return *entry;
}

// How long WaitForWorkers waits before it reports the pool stuck.
inline constexpr std::chrono::seconds kWorkerStallLimit{5};

// Returns once every task posted to `pool` before the call has run and dropped its references (a
// stream handler freed): a background task is posted and waited for, which on a pool of one
// worker runs only after every urgent task and every earlier background task. Aborts if it has not
// run within kWorkerStallLimit.
inline void WaitForWorkers(service::WorkerPool& pool) {
  if (pool.size() != 1) SetupFailed("WaitForWorkers needs a pool of one worker");
  struct Barrier {
    std::mutex mutex;
    std::condition_variable reached;
    bool done = false;
  };
  auto barrier = std::make_shared<Barrier>();
  pool.PostBackground([barrier] {
    std::lock_guard<std::mutex> lock(barrier->mutex);
    barrier->done = true;
    barrier->reached.notify_all();
  });
  std::unique_lock<std::mutex> lock(barrier->mutex);
  if (!barrier->reached.wait_for(lock, kWorkerStallLimit, [&] { return barrier->done; })) {
    std::fprintf(stderr, "the worker pool is stuck: a task posted to it never ran\n");
    std::abort();
  }
}

}  // namespace deform::fuzz
