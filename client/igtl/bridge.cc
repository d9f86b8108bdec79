#include "igtl/bridge.h"

#include <spdlog/spdlog.h>
#include <unistd.h>

#include <chrono>
#include <condition_variable>
#include <cstring>
#include <memory>
#include <mutex>
#include <thread>

#include "cli/command_line.h"
#include "igtl/frame_packer.h"
#include "igtl/igtl_messages.h"
#include "igtl/joint_angle_input.h"
#include "igtl/receiver_hub.h"
#include "service/base/log_text.h"

namespace deform::igtl_bridge {
namespace {

using Clock = std::chrono::steady_clock;
using service::EscapeForLog;

constexpr char kProgram[] = "deform-igtl-bridge";
constexpr int kFloatsPerBone = 12;  // EncodedPositions.bone_transforms: row-major 3 x 4 [R | t]

// The messages of one frame: its points (or, given `triangles`, the full POLYDATA "Skin"), then
// one TRANSFORM per bone when the frame carries them.
std::string PackFrame(const deform::v1::DeformFrame& frame, const RasFrame& ras,
                      const std::vector<std::string>& bone_names, const std::string* triangles) {
  std::string bytes = triangles != nullptr ? PackTopology(frame.positions(), *triangles, ras)
                                           : PackPoints(frame.positions(), ras);
  const auto& floats = frame.encoded().bone_transforms();
  if (bone_names.empty() || floats.size() != kFloatsPerBone * static_cast<int>(bone_names.size())) {
    return bytes;
  }
  for (std::size_t b = 0; b < bone_names.size(); ++b) {
    const float* m = floats.data() + kFloatsPerBone * b;
    const float rotation[9] = {m[0], m[1], m[2], m[4], m[5], m[6], m[8], m[9], m[10]};
    const float translation[3] = {m[3], m[7], m[11]};
    bytes += PackTransform(bone_names[b], ras.MapMotion(rotation, translation));
  }
  return bytes;
}

// The poses sent on the stream: the receivers' angles, numbered in the order sent.
class PoseSender {
 public:
  PoseSender(client::DeformStream* stream, deform::v1::MeshSummary summary)
      : stream_(stream), input_(std::move(summary)) {}

  // A receiver's STRING: applied and sent at once, or logged and dropped.
  void OnString(const std::string& peer, const std::string& text) {
    std::lock_guard<std::mutex> lock(mu_);
    std::string error;
    if (!input_.Apply(text, &error)) {
      spdlog::warn("OpenIGTLink: receiver {}: joint angles {} refused: {}", peer,
                   EscapeForLog(text), EscapeForLog(error));
      return;
    }
    spdlog::info("OpenIGTLink: receiver {}: joint angles {}", peer, EscapeForLog(text));
    SendLocked();
  }

  void SendCurrent() {
    std::lock_guard<std::mutex> lock(mu_);
    SendLocked();
  }

 private:
  void SendLocked() {
    deform::v1::PoseUpdate pose = input_.Pose();
    pose.set_sequence(++sequence_);
    pose.set_client_timestamp_ns(client::MonotonicNanos());
    stream_->SendPose(pose);
  }

  client::DeformStream* const stream_;
  std::mutex mu_;
  JointAngleInput input_;       // guarded by mu_
  std::uint64_t sequence_ = 0;  // guarded by mu_
};

// The stream's end, for the run's loop.
class StreamEnd {
 public:
  void Set(const grpc::Status& status) {
    std::lock_guard<std::mutex> lock(mu_);
    status_ = status;
    ended_ = true;
    changed_.notify_all();
  }
  // Waits until `deadline` or the end; true once ended.
  bool WaitUntil(Clock::time_point deadline) {
    std::unique_lock<std::mutex> lock(mu_);
    return changed_.wait_until(lock, deadline, [&] { return ended_; });
  }
  grpc::Status status() {
    std::lock_guard<std::mutex> lock(mu_);
    return status_;
  }

 private:
  std::mutex mu_;
  std::condition_variable changed_;
  bool ended_ = false;
  grpc::Status status_;
};

int Fail(grpc::StatusCode code, const std::string& message) {
  return cli::ReportFailure(kProgram, grpc::Status(code, message));
}

}  // namespace

int RunBridge(client::DeformClient& client, const deform::v1::MeshSummary& summary,
              const BridgeSettings& settings, const std::atomic<bool>& stop) {
  deform::v1::GetMeshInfoResponse geometry;
  const grpc::Status fetched =
      client.GetMeshInfo(summary.mesh_id(), /*include_geometry=*/true, &geometry);
  if (!fetched.ok()) return cli::ReportFailure(kProgram, fetched);
  const std::string topology =
      PackTopology(geometry.rest_positions(), geometry.triangles(), settings.frame);
  const std::vector<std::string> bone_names = BoneDeviceNames(summary);

  int port = 0;
  std::string error;
  const int listen_fd = ListenTcp(settings.listen_host, settings.listen_port, &port, &error);
  if (listen_fd < 0) return Fail(grpc::StatusCode::UNAVAILABLE, error);

  StreamEnd end;
  std::shared_ptr<ReceiverHub> hub;  // set before the first pose, so before any frame
  const std::string* frame_triangles = settings.full_frames ? &geometry.triangles() : nullptr;
  FramePacker packer(
      [&](const deform::v1::DeformFrame& frame) {
        return PackFrame(frame, settings.frame, bone_names, frame_triangles);
      },
      [&hub](std::shared_ptr<const std::string> bytes) { hub->Publish(std::move(bytes)); });
  client::DeformClient::StreamCallbacks callbacks;
  callbacks.on_frame = [&packer](const deform::v1::DeformFrame& frame) { packer.Offer(frame); };
  callbacks.on_notice = [](const deform::v1::Notice& notice) {
    if (notice.kind() == deform::v1::Notice::KIND_POSE_REJECTED) {
      spdlog::warn("deform stream: pose {} rejected: {}", notice.sequence(),
                   EscapeForLog(notice.message()));
    }
  };
  callbacks.on_done = [&end](const grpc::Status& status) { end.Set(status); };
  client::DeformClient::StreamOptions options;
  options.encoding = deform::v1::FRAME_ENCODING_PREDICTED;
  std::unique_ptr<client::DeformStream> stream =
      client.OpenStream(summary.mesh_id(), std::move(callbacks), options);
  if (stream == nullptr) {
    ::close(listen_fd);
    return Fail(grpc::StatusCode::INTERNAL, "the deform stream could not be opened");
  }
  PoseSender poses(stream.get(), summary);
  hub = std::make_shared<ReceiverHub>(
      listen_fd, topology, settings.max_receivers,
      [&poses](const std::string& peer, const std::string& text) { poses.OnString(peer, text); });
  spdlog::info(
      "mesh {} ({} vertices, {} triangles, {} bones); topology POLYDATA {} bytes; RAS at {} mm "
      "per model unit",
      summary.mesh_id(), summary.vertex_count(), summary.triangle_count(), bone_names.size(),
      topology.size(), settings.frame.mm_per_unit());
  hub->Start();
  spdlog::info("OpenIGTLink: listening on {}:{}", settings.listen_host, port);

  poses.SendCurrent();  // the rest pose: the first frame
  const Clock::time_point t0 = Clock::now();
  const bool ticking = settings.rate_hz > 0;
  const std::chrono::duration<double> period(ticking ? 1.0 / settings.rate_hz : 0.1);
  bool ended = false;
  for (std::int64_t k = 1; !stop.load() && !ended; ++k) {
    ended = end.WaitUntil(t0 + std::chrono::duration_cast<Clock::duration>(k * period));
    if (!ended && ticking && !stop.load()) poses.SendCurrent();
    // Ticks missed (a stalled machine) are skipped, not made up for with a burst of poses.
    const auto due =
        static_cast<std::int64_t>(std::chrono::duration<double>(Clock::now() - t0) / period);
    if (due > k) k = due;
  }
  if (!ended) {
    stream->Close();
    if (!end.WaitUntil(Clock::now() + std::chrono::seconds(5))) stream->Cancel();
  }
  const grpc::Status final_status = stream->Wait();
  packer.Stop();
  hub->Stop();
  spdlog::info("frames skipped while packing was busy: {}", packer.skipped());
  if (ended) {
    return cli::ReportFailure(
        kProgram, final_status.ok()
                      ? grpc::Status(grpc::StatusCode::UNAVAILABLE, "the deform stream ended")
                      : final_status);
  }
  spdlog::info("stopped");
  return 0;
}

}  // namespace deform::igtl_bridge
