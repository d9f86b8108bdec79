#include "loadtest/load_runner.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <memory>
#include <thread>

#include "lib/flexion_trajectory.h"

namespace deform::loadtest {
namespace {

using Clock = std::chrono::steady_clock;

// When things happen. Every stream sends poses at ticks k = 0 .. total_ticks - 1; ticks from
// warmup_ticks on (sequences from warmup_ticks + 1) are measured.
struct Schedule {
  std::int64_t warmup_ticks = 0;
  std::int64_t total_ticks = 0;
  Clock::time_point t0;
  std::int64_t measure_start_ns = 0;  // tick warmup_ticks, on MonotonicNanos()'s clock
  std::int64_t measure_end_ns = 0;    // tick total_ticks
};

Schedule MakeSchedule(const LoadPlan& plan) {
  Schedule schedule;
  schedule.warmup_ticks = static_cast<std::int64_t>(std::ceil(plan.warmup_s * plan.rate_hz - 1e-9));
  const auto measured_ticks = std::max<std::int64_t>(
      1, static_cast<std::int64_t>(std::ceil(plan.duration_s * plan.rate_hz - 1e-9)));
  schedule.total_ticks = schedule.warmup_ticks + measured_ticks;
  schedule.t0 = Clock::now();
  const std::int64_t t0_ns = client::MonotonicNanos();
  const double tick_ns = 1e9 / plan.rate_hz;
  schedule.measure_start_ns =
      t0_ns + static_cast<std::int64_t>(static_cast<double>(schedule.warmup_ticks) * tick_ns);
  schedule.measure_end_ns =
      t0_ns + static_cast<std::int64_t>(static_cast<double>(schedule.total_ticks) * tick_ns);
  return schedule;
}

// One stream's live state on the sender's side.
struct StreamSlot {
  std::unique_ptr<StreamRecorder> recorder;
  std::unique_ptr<client::DeformStream> stream;
  bool open = true;
  std::uint64_t last_sequence = 0;
  std::int64_t last_send_ns = 0;
  std::int64_t next_stiffness_ns = 0;
  std::size_t stiffness_turn = 0;
  StreamOutcome outcome;
};

deform::v1::PoseUpdate MakePose(const LoadPlan& plan, double t_seconds) {
  deform::v1::PoseUpdate pose;
  deform::v1::JointAngle* angle = pose.add_angles();
  angle->set_joint(plan.posed.joint);
  angle->set_axis(plan.posed.axis);
  angle->set_degrees(client::FlexionDegreesAt(t_seconds, plan.cycle_s, plan.peak_degrees));
  return pose;
}

std::vector<StreamSlot> OpenStreams(client::DeformClient& client, const LoadPlan& plan) {
  const auto expected_frames =
      static_cast<std::size_t>(std::ceil(plan.duration_s * plan.rate_hz)) + 16;
  std::vector<StreamSlot> slots(static_cast<std::size_t>(plan.streams));
  for (StreamSlot& slot : slots) {
    slot.recorder = std::make_unique<StreamRecorder>(expected_frames, plan.vertex_count);
    StreamRecorder* recorder = slot.recorder.get();
    client::DeformClient::StreamCallbacks callbacks;
    callbacks.on_frame = [recorder](const deform::v1::DeformFrame& f) { recorder->OnFrame(f); };
    callbacks.on_notice = [recorder](const deform::v1::Notice& n) { recorder->OnNotice(n); };
    callbacks.on_done = [recorder](const grpc::Status& s) { recorder->OnDone(s); };
    callbacks.on_reconnect = [recorder](const grpc::Status&, int) { recorder->OnReconnect(); };
    client::DeformClient::StreamOptions options;
    options.encoding = plan.encoding;
    options.reconnect.enabled = plan.reconnect;
    slot.stream = client.OpenStream(plan.mesh_id, std::move(callbacks), options);
    slot.open = slot.stream != nullptr;
  }
  return slots;
}

// Sends stiffness updates that are due on `slot` at `now_ns`.
void SendDueStiffness(const LoadPlan& plan, std::int64_t now_ns, std::int64_t measure_end_ns,
                      StreamSlot* slot) {
  if (plan.stiffness_every_s <= 0 || plan.stiffness_updates.empty()) return;
  const auto every_ns = static_cast<std::int64_t>(plan.stiffness_every_s * 1e9);
  while (slot->open && slot->next_stiffness_ns <= now_ns &&
         slot->next_stiffness_ns < measure_end_ns) {
    const auto& update =
        plan.stiffness_updates[slot->stiffness_turn % plan.stiffness_updates.size()];
    if (!slot->stream->SendStiffness(update)) {
      slot->open = false;
      return;
    }
    ++slot->outcome.stiffness_sent;
    ++slot->stiffness_turn;
    slot->next_stiffness_ns += every_ns;
  }
}

// Slot j = k * streams + i is stream i's pose k, due at t0 + j * period / streams. Returns the
// worst lateness of a send, in milliseconds.
double SendAll(const LoadPlan& plan, const Schedule& schedule, std::vector<StreamSlot>* slots) {
  const auto streams = static_cast<std::int64_t>(slots->size());
  const std::chrono::duration<double> slot_period(1.0 /
                                                  (plan.rate_hz * static_cast<double>(streams)));
  double lag_max_ms = 0;
  for (std::int64_t j = 0; j < schedule.total_ticks * streams; ++j) {
    const std::int64_t k = j / streams;
    StreamSlot& slot = (*slots)[static_cast<std::size_t>(j % streams)];
    const Clock::time_point due =
        schedule.t0 + std::chrono::duration_cast<Clock::duration>(j * slot_period);
    std::this_thread::sleep_until(due);
    if (!slot.open) continue;
    lag_max_ms =
        std::max(lag_max_ms, std::chrono::duration<double, std::milli>(Clock::now() - due).count());

    SendDueStiffness(plan, client::MonotonicNanos(), schedule.measure_end_ns, &slot);
    if (!slot.open) continue;
    const double phase_s =
        plan.cycle_s * static_cast<double>(j % streams) / static_cast<double>(streams);
    deform::v1::PoseUpdate pose = MakePose(plan, static_cast<double>(k) / plan.rate_hz + phase_s);
    const std::int64_t send_ns = client::MonotonicNanos();
    pose.set_sequence(static_cast<std::uint64_t>(k) + 1);
    pose.set_client_timestamp_ns(send_ns);
    if (!slot.stream->SendPose(pose)) {
      slot.open = false;
      continue;
    }
    slot.last_sequence = pose.sequence();
    slot.last_send_ns = send_ns;
    ++slot.outcome.poses_sent_total;
    if (k >= schedule.warmup_ticks) ++slot.outcome.poses_sent;
  }
  return lag_max_ms;
}

// Waits for the last frames, half-closes, waits for the ends, cancels stragglers.
void DrainAndClose(const LoadPlan& plan, std::vector<StreamSlot>* slots) {
  const auto drain =
      std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(plan.drain_s));
  const Clock::time_point answers_deadline = Clock::now() + drain;
  for (StreamSlot& slot : *slots) {
    if (slot.stream != nullptr && slot.last_sequence > 0) {
      slot.recorder->WaitAnswered(slot.last_sequence, answers_deadline);
    }
  }
  for (StreamSlot& slot : *slots) {
    if (slot.stream != nullptr) slot.stream->Close();
  }
  const Clock::time_point close_deadline = Clock::now() + drain;
  for (StreamSlot& slot : *slots) {
    if (slot.stream == nullptr) {
      slot.outcome.status = grpc::Status(grpc::StatusCode::INTERNAL, "stream not opened");
      continue;
    }
    const bool finished = slot.recorder->WaitDone(close_deadline);
    if (!finished) slot.stream->Cancel();
    slot.outcome.status = slot.stream->Wait();
    if (!finished) {
      slot.outcome.status = grpc::Status(grpc::StatusCode::DEADLINE_EXCEEDED,
                                         "the stream did not finish after the half-close");
    }
  }
}

}  // namespace

RunOutcome RunLoad(client::DeformClient& client, const LoadPlan& plan) {
  std::vector<StreamSlot> slots = OpenStreams(client, plan);

  // The schedule starts once every stream is open.
  const Schedule schedule = MakeSchedule(plan);
  const auto first_measured_sequence = static_cast<std::uint64_t>(schedule.warmup_ticks) + 1;
  const auto every_ns = static_cast<std::int64_t>(plan.stiffness_every_s * 1e9);
  for (std::size_t i = 0; i < slots.size(); ++i) {
    slots[i].recorder->SetMeasureStart(first_measured_sequence, schedule.measure_start_ns);
    slots[i].next_stiffness_ns =
        schedule.measure_start_ns +
        every_ns * static_cast<std::int64_t>(i) / static_cast<std::int64_t>(slots.size());
  }

  RunOutcome run;
  run.send_lag_max_ms = SendAll(plan, schedule, &slots);
  DrainAndClose(plan, &slots);

  for (StreamSlot& slot : slots) {
    StreamOutcome outcome = std::move(slot.outcome);
    outcome.stats = slot.recorder->Snapshot();
    const std::int64_t silent_from =
        std::max(outcome.stats.last_receipt_ns, schedule.measure_start_ns);
    const double tail_gap_ms = static_cast<double>(slot.last_send_ns - silent_from) * 1e-6;
    outcome.max_gap_ms = std::max(outcome.stats.max_gap_ms, tail_gap_ms);
    run.streams.push_back(std::move(outcome));
  }
  return run;
}

}  // namespace deform::loadtest
