// deform-contact-latency: the loopback round trip of QueryContact against a running deformd. Loads
// the knee phantom, opens a Deform stream that bends the knee at 90 poses a second, and queries a
// sphere on the thigh's front against that stream's latest frame at a fixed rate; prints the
// round trips' percentiles.
//
//   deform-contact-latency TARGET [SECONDS=10] [RATE_HZ=1000] [VERTICES=800]
//
// Exit code 1 with a stderr line for a bad argument or a failed call.
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "deform_client.h"

namespace {

using Clock = std::chrono::steady_clock;

int Fail(const std::string& what) {
  std::fprintf(stderr, "deform-contact-latency: %s\n", what.c_str());
  return 1;
}

double Percentile(std::vector<double> values, double fraction) {
  std::sort(values.begin(), values.end());
  const auto index = static_cast<std::size_t>(fraction * static_cast<double>(values.size() - 1));
  return values[index];
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) return Fail("usage: deform-contact-latency TARGET [SECONDS] [RATE_HZ] [VERTICES]");
  const std::string target = argv[1];
  const double seconds = argc > 2 ? std::atof(argv[2]) : 10;
  const double rate = argc > 3 ? std::atof(argv[3]) : 1000;
  const int vertices = argc > 4 ? std::atoi(argv[4]) : 800;
  if (!(seconds > 0) || !(rate > 0) || vertices < 0)
    return Fail("bad SECONDS, RATE_HZ or VERTICES");
  deform::client::DeformClient client(target);
  if (!client.WaitForReady(30'000)) return Fail("no server at " + target);
  deform::v1::MeshSummary summary;
  const grpc::Status loaded = client.LoadPhantom(vertices, {}, &summary);
  if (!loaded.ok()) return Fail("LoadMesh: " + loaded.error_message());

  std::atomic<std::uint64_t> stream_id{0};
  deform::client::DeformClient::StreamCallbacks callbacks;
  callbacks.on_frame = [&](const deform::v1::DeformFrame& frame) {
    stream_id.store(frame.stream_id());
  };
  auto stream = client.OpenStream(summary.mesh_id(), callbacks);
  std::atomic<bool> posing{true};
  std::thread poser([&] {
    std::uint64_t sequence = 0;
    for (auto next = Clock::now(); posing.load(); next += std::chrono::microseconds(11'111)) {
      deform::v1::PoseUpdate pose;
      pose.set_sequence(++sequence);
      std::string error;
      deform::client::ParsePoseAngles(
          "knee:flexion:" + std::to_string(45 + 45 * ((sequence / 90) % 2 == 0 ? 1 : -1) *
                                                    static_cast<double>(sequence % 90) / 90.0),
          &pose, &error);
      if (!stream->SendPose(pose)) break;
      std::this_thread::sleep_until(next);
    }
  });
  while (stream_id.load() == 0) std::this_thread::sleep_for(std::chrono::milliseconds(5));

  deform::v1::ContactQueryStart start;
  start.set_mesh_id(summary.mesh_id());
  start.set_deform_stream_id(stream_id.load());
  std::unique_ptr<deform::client::ContactQuery> query;
  const grpc::Status opened = client.OpenContactQuery(start, &query);
  if (!opened.ok()) return Fail("QueryContact: " + opened.error_message());
  deform::v1::ToolState tool;
  tool.set_shape(deform::v1::ToolState::SHAPE_SPHERE);
  tool.mutable_center()->set_y(6);
  tool.mutable_center()->set_z(0.86);
  tool.set_radius(0.3);

  std::vector<double> round_trips_ms;
  std::uint64_t frames_seen = 0, last_frame = 0;
  const auto period = std::chrono::duration<double>(1.0 / rate);
  const auto begin = Clock::now();
  auto next = begin;
  while (Clock::now() - begin < std::chrono::duration<double>(seconds)) {
    deform::v1::ContactResult result;
    const auto sent = Clock::now();
    const grpc::Status queried = query->Query(tool, &result);
    const auto received = Clock::now();
    if (!queried.ok()) return Fail("query: " + queried.error_message());
    round_trips_ms.push_back(std::chrono::duration<double, std::milli>(received - sent).count());
    if (result.frame_number() != last_frame) {
      ++frames_seen;
      last_frame = result.frame_number();
    }
    next += std::chrono::duration_cast<Clock::duration>(period);
    std::this_thread::sleep_until(next);
  }
  posing.store(false);
  poser.join();
  (void)query->Close();
  stream->Close();
  (void)stream->Wait();
  std::printf(
      "deform-contact-latency: %zu queries in %.1f s at %.0f Hz against a Deform stream at 90 Hz "
      "(%llu newer frames refitted), round trip ms: p50 %.3f p99 %.3f max %.3f\n",
      round_trips_ms.size(), seconds, rate, static_cast<unsigned long long>(frames_seen),
      Percentile(round_trips_ms, 0.5), Percentile(round_trips_ms, 0.99),
      Percentile(round_trips_ms, 1.0));
  return 0;
}
