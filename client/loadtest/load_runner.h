// Runs a load plan: opens the streams, drives every stream's sends from one thread on a fixed
// schedule, drains, closes, and returns what each stream saw.
#pragma once

#include <grpcpp/support/status.h>

#include <cstdint>
#include <vector>

#include "lib/deform_client.h"
#include "loadtest/load_plan.h"
#include "loadtest/stream_recorder.h"

namespace deform::loadtest {

struct StreamOutcome {
  StreamStats stats;
  std::uint64_t poses_sent = 0;        // measured poses accepted by SendPose
  std::uint64_t poses_sent_total = 0;  // including the warm-up
  std::uint64_t stiffness_sent = 0;
  // The stream's end: its final status, or DEADLINE_EXCEEDED when it had to be cancelled because
  // it did not finish after the half-close.
  grpc::Status status;
  // max_gap_ms extended to the silence between the stream's last frame and its last send.
  double max_gap_ms = 0;
};

struct RunOutcome {
  std::vector<StreamOutcome> streams;
  double send_lag_max_ms = 0;  // worst lateness of a send against its schedule
};

RunOutcome RunLoad(client::DeformClient& client, const LoadPlan& plan);

}  // namespace deform::loadtest
