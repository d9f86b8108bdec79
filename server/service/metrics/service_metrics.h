// The service's Prometheus metrics (prometheus-cpp's registry; served by MetricsEndpoint).
//
// What is counted, and where (metric names as exposed):
//  - deformd_frames_sent_total{encoding}, deformd_frame_bytes_sent_total{encoding}: Deform frames
//    whose write completed (what clients received), and their serialized DeformResponse bytes;
//    encoding is float32, quantized or predicted.
//  - deformd_frame_server_seconds: histogram of a written frame's server time (queue, right-hand
//    side, solve and encode: DeformFrame.timings), the sum of its two parts:
//    deformd_frame_queue_seconds (FrameTimings.queue_ms: the pose's wait from its arrival to the
//    start of its solve) and deformd_frame_compute_seconds (rhs_ms + solve_ms + constraint_ms +
//    encode_ms: from the solve's start to the frame's packing).
//  - deformd_frame_constraint_seconds: histogram of a written constrained frame's constraint time
//    (FrameTimings.constraint_ms); deformd_frames_unresolved_total: written frames whose skin
//    was left inside a bone (FrameConstraints.unresolved).
//  - deformd_poses_skipped_total: poses replaced by a newer one before they were solved (the sum
//    of written frames' skipped_poses).
//  - deformd_notices_sent_total{kind}: notices written (pose_rejected, stiffness_applied,
//    stiffness_rejected).
//  - deformd_rpcs_total{method,code}: finished RPCs by method (the five DeformService methods by
//    name, every other method as "other") and status code name ("OK", "NOT_FOUND", ...).
//  - deformd_build_seconds{result}: mesh builds (LoadMesh, --preload, --store), ok or error.
//  - deformd_refactorization_seconds: stiffness refactorizations of Deform streams.
//  - Gauges set at each scrape (SetGauges): deformd_streams_open, deformd_meshes_loaded,
//    deformd_loads_in_progress, deformd_memory_budget_used_bytes,
//    deformd_memory_budget_reserved_bytes, deformd_memory_budget_streams_bytes,
//    deformd_memory_budget_bytes,
//    deformd_notice_backlog_bytes; deformd_mesh_streams_open{mesh} for each loaded mesh (its
//    id), so that a cluster's operator sees which replica serves which mesh's streams.
//  - deformd_refused_total{reason}: what any peer can cause at will, counted whether or not it
//    was logged (ServiceContext::CountRefusal bounds the lines): unauthenticated calls,
//    HTTP connections over --http-max-connections, HTTP requests for another Host or Origin,
//    HTTP requests over the header or body limit.
//  - deformd_build_info{version,commit}: always 1; the build's version and commit as labels
//    (core/base/build_info.h), as --version prints them.
//  - The standard gRPC server metrics (go-grpc-prometheus' names and labels), for every method
//    of grpc_methods.h (grpc_type, grpc_service, grpc_method): grpc_server_started_total,
//    grpc_server_handled_total{...,grpc_code}, grpc_server_msg_received_total,
//    grpc_server_msg_sent_total and grpc_server_handling_seconds (a histogram from the call's
//    start to its status), counted by RpcMetricsInterceptorFactory for gRPC calls only (the
//    WebSocket and HTTP calls are in deformd_rpcs_total).
//  - Prometheus' standard process_* metrics (process_collector.h), read at each scrape.
//  - deformd_tls_certificate_expiry_seconds: the served certificate's end of validity, Unix
//    seconds (as the blackbox exporter's probe_ssl_earliest_cert_expiry; alert on it minus
//    time()); absent without TLS (SetCertificateExpiry).
//
// A client's errors as deform-loadtest counts them are the Deform RPCs that ended with a code
// other than OK plus the notices pose_rejected and stiffness_rejected.
//
// Thread safety: every method may be called from any thread. The per-frame calls (FrameWritten,
// ConstrainedFrameWritten, NoticeWritten) take no lock and allocate nothing: their histograms are
// AtomicHistograms, and every labelled series they touch is created in the constructor. The
// per-RPC calls (RpcFinished, the Grpc* calls) allocate nothing either; GrpcHandled's histogram
// (prometheus-cpp's) locks its series' mutex once per call.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "core/base/status.h"
#include "service/base/annotated_mutex.h"
#include "service/base/thread_annotations.h"
#include "service/metrics/atomic_histogram.h"
#include "service/metrics/grpc_methods.h"

namespace prometheus {
class Collectable;
class Counter;
class Gauge;
class Histogram;
class Registry;
}  // namespace prometheus

namespace deform::service {

class ServiceMetrics {
 public:
  // The encodings and notice kinds as the proto numbers them (FrameEncoding, Notice.Kind).
  static constexpr int kEncodings = 4;    // index 0 (unspecified) counts as float32
  static constexpr int kNoticeKinds = 5;  // index 0 (unspecified) is never written
  static constexpr int kStatusCodes = kCanonicalStatusCodes;  // grpc::StatusCode 0..16
  static constexpr int kMethods = 7;  // six DeformService methods and "other"
  static constexpr int kGrpcMethods = static_cast<int>(kServedGrpcMethods.size());

  // deformd_refused_total's reasons.
  enum class Refusal {
    kUnauthenticated,
    kHttpConnectionLimit,
    kHttpHostOrOrigin,
    kHttpTooLarge,
    kMetricsScrape,        // a scrape without a valid metrics or operator token
    kGrpcConnectionLimit,  // a gRPC connection beyond --max-connections(-per-address)
    kNoDescriptors,        // a waiting connection closed unserved: out of open files
  };
  static constexpr int kRefusals = 7;
  static const char* RefusalName(Refusal reason);

  ServiceMetrics();
  ~ServiceMetrics();
  ServiceMetrics(const ServiceMetrics&) = delete;
  ServiceMetrics& operator=(const ServiceMetrics&) = delete;

  // A Deform frame's write completed: `encoding` as in FrameEncoding (out of range: float32),
  // `bytes` its serialized size, `queue_seconds` and `compute_seconds` the two parts of its server
  // time (see above), `skipped_poses` its count.
  void FrameWritten(int encoding, std::size_t bytes, double queue_seconds, double compute_seconds,
                    std::uint64_t skipped_poses);
  // A written frame's constraints (a mesh with constraints): their time, and whether they left
  // skin inside a bone.
  void ConstrainedFrameWritten(double constraint_seconds, bool unresolved);
  // A notice's write completed; `kind` as in Notice.Kind (out of range: ignored).
  void NoticeWritten(int kind);
  // An RPC finished: `method` is the full name ("/deform.v1.DeformService/Deform"), `code` the
  // status code (out of range: UNKNOWN).
  void RpcFinished(std::string_view method, int code);
  // A gRPC call of kServedGrpcMethods[grpc_method] (ServedGrpcMethodIndex; out of range:
  // ignored) started, received or sent a message, or sent its status `code` (out of range:
  // UNKNOWN) `seconds` after it started.
  void GrpcStarted(int grpc_method);
  void GrpcMessageReceived(int grpc_method);
  void GrpcMessageSent(int grpc_method);
  void GrpcHandled(int grpc_method, int code, double seconds);
  void Refused(Refusal reason);
  void BuildFinished(double seconds, bool ok);
  void RefactorizationFinished(double seconds);

  // The gauges, from the caller's snapshot of the service (before each scrape).
  struct Gauges {
    int streams_open = 0;
    int meshes_loaded = 0;
    int loads_in_progress = 0;
    std::size_t memory_used_bytes = 0;
    std::size_t memory_reserved_bytes = 0;
    std::size_t memory_streams_bytes = 0;
    std::size_t memory_budget_bytes = 0;
    std::int64_t notice_backlog_bytes = 0;
    std::vector<std::pair<std::string, int>> mesh_streams;  // mesh id, its open streams
  };
  void SetGauges(const Gauges& gauges);
  // The served TLS certificate's end of validity (Unix seconds); called once, when TLS starts.
  void SetCertificateExpiry(std::int64_t not_after_unix_seconds);

  // Everything in Prometheus' text exposition format (version 0.0.4).
  std::string Serialize() const;

 private:
  std::shared_ptr<prometheus::Registry> registry_;
  std::array<prometheus::Counter*, kEncodings> frames_sent_{};
  std::array<prometheus::Counter*, kEncodings> frame_bytes_sent_{};
  prometheus::Counter* poses_skipped_ = nullptr;
  AtomicHistogram frame_server_seconds_;
  AtomicHistogram frame_queue_seconds_;
  AtomicHistogram frame_compute_seconds_;
  AtomicHistogram frame_constraint_seconds_;
  prometheus::Counter* frames_unresolved_ = nullptr;
  std::array<prometheus::Counter*, kNoticeKinds> notices_sent_{};
  std::array<std::array<prometheus::Counter*, kStatusCodes>, kMethods> rpcs_{};
  std::array<prometheus::Counter*, kRefusals> refused_{};
  struct GrpcSeries {
    prometheus::Counter* started = nullptr;
    prometheus::Counter* received = nullptr;
    prometheus::Counter* sent = nullptr;
    std::array<prometheus::Counter*, kStatusCodes> handled{};
    prometheus::Histogram* handling_seconds = nullptr;
  };
  std::array<GrpcSeries, kGrpcMethods> grpc_{};
  std::unique_ptr<prometheus::Collectable> process_;
  prometheus::Histogram* build_ok_seconds_ = nullptr;
  prometheus::Histogram* build_error_seconds_ = nullptr;
  prometheus::Histogram* refactorization_seconds_ = nullptr;
  prometheus::Gauge* streams_open_ = nullptr;
  prometheus::Gauge* meshes_loaded_ = nullptr;
  prometheus::Gauge* loads_in_progress_ = nullptr;
  prometheus::Gauge* memory_used_ = nullptr;
  prometheus::Gauge* memory_reserved_ = nullptr;
  prometheus::Gauge* memory_streams_ = nullptr;
  prometheus::Gauge* memory_budget_ = nullptr;
  prometheus::Gauge* notice_backlog_ = nullptr;
  prometheus::Gauge* certificate_expiry_ = nullptr;  // added by SetCertificateExpiry
  mutable Mutex mesh_streams_mutex_;
  std::vector<std::pair<std::string, int>> mesh_streams_ DEFORM_GUARDED_BY(mesh_streams_mutex_);
};

}  // namespace deform::service
