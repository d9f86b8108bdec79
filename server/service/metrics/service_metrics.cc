#include "service/metrics/service_metrics.h"

#include <prometheus/collectable.h>
#include <prometheus/counter.h>
#include <prometheus/gauge.h>
#include <prometheus/histogram.h>
#include <prometheus/registry.h>
#include <prometheus/text_serializer.h>

#include <iterator>
#include <vector>

#include "core/base/build_info.h"
#include "core/base/status.h"
#include "service/metrics/process_collector.h"

namespace deform::service {
namespace {

constexpr std::array<const char*, ServiceMetrics::kEncodings> kEncodingNames = {
    "float32", "float32", "quantized", "predicted"};
constexpr std::array<const char*, ServiceMetrics::kNoticeKinds> kNoticeKindNames = {
    "unspecified", "pose_rejected", "stiffness_rejected", "stiffness_applied",
    "credentials_revoked"};
// The methods labelled by name; any other (health, reflection, unknown) is "other", so a client
// cannot grow the number of series.
constexpr std::array<const char*, ServiceMetrics::kMethods - 1> kMethodNames = {
    "LoadMesh", "GetMeshInfo", "ListMeshes", "UnloadMesh", "Deform", "QueryContact"};
constexpr std::string_view kServicePrefix = "/deform.v1.DeformService/";

int MethodIndex(std::string_view method) {
  if (method.substr(0, kServicePrefix.size()) == kServicePrefix) {
    const std::string_view name = method.substr(kServicePrefix.size());
    for (int i = 0; i < static_cast<int>(kMethodNames.size()); ++i) {
      if (name == kMethodNames[i]) return i;
    }
  }
  return ServiceMetrics::kMethods - 1;
}

prometheus::Histogram::BucketBoundaries Exponential(double first, double factor, int count) {
  prometheus::Histogram::BucketBoundaries bounds;
  double bound = first;
  for (int i = 0; i < count; ++i, bound *= factor) bounds.push_back(bound);
  return bounds;
}

}  // namespace

ServiceMetrics::ServiceMetrics()
    : registry_(std::make_shared<prometheus::Registry>()),
      // The per-frame histograms take no lock (AtomicHistogram); queue and compute time are the
      // server time's two parts, on its buckets.
      frame_server_seconds_(
          "deformd_frame_server_seconds",
          "Server time of a written frame: queue, right-hand side, solve and encode",
          Exponential(0.000125, 2, 14)),
      frame_queue_seconds_(
          "deformd_frame_queue_seconds",
          "Queue time of a written frame: from the pose's arrival to its solve's start",
          Exponential(0.000125, 2, 14)),
      frame_compute_seconds_(
          "deformd_frame_compute_seconds",
          "Compute time of a written frame: right-hand side, solve, constraints, encode",
          Exponential(0.000125, 2, 14)),
      frame_constraint_seconds_(
          "deformd_frame_constraint_seconds",
          "Constraint time of a written constrained frame (bone contacts, volume)",
          Exponential(0.00003125, 2, 14)),
      process_(MakeProcessCollector()) {
  using prometheus::BuildCounter;
  using prometheus::BuildGauge;
  using prometheus::BuildHistogram;
  auto& frames = BuildCounter()
                     .Name("deformd_frames_sent_total")
                     .Help("Deform frames written to clients, by encoding")
                     .Register(*registry_);
  auto& frame_bytes = BuildCounter()
                          .Name("deformd_frame_bytes_sent_total")
                          .Help("Serialized bytes of the Deform frames written, by encoding")
                          .Register(*registry_);
  for (int i = 0; i < kEncodings; ++i) {
    // Index 0 shares float32's series (an unset encoding is float32).
    frames_sent_[i] = i == 0 ? nullptr : &frames.Add({{"encoding", kEncodingNames[i]}});
    frame_bytes_sent_[i] = i == 0 ? nullptr : &frame_bytes.Add({{"encoding", kEncodingNames[i]}});
  }
  frames_sent_[0] = frames_sent_[1];
  frame_bytes_sent_[0] = frame_bytes_sent_[1];
  frames_unresolved_ = &BuildCounter()
                            .Name("deformd_frames_unresolved_total")
                            .Help("Written frames whose constraints left skin inside a bone")
                            .Register(*registry_)
                            .Add({});
  poses_skipped_ = &BuildCounter()
                        .Name("deformd_poses_skipped_total")
                        .Help("Poses replaced by a newer pose before they were solved")
                        .Register(*registry_)
                        .Add({});
  auto& notices = BuildCounter()
                      .Name("deformd_notices_sent_total")
                      .Help("Notices written to Deform clients, by kind")
                      .Register(*registry_);
  for (int i = 1; i < kNoticeKinds; ++i) {
    notices_sent_[i] = &notices.Add({{"kind", kNoticeKindNames[i]}});
  }
  auto& rpcs = BuildCounter()
                   .Name("deformd_rpcs_total")
                   .Help("Finished RPCs by method and status code")
                   .Register(*registry_);
  for (int m = 0; m < kMethods; ++m) {
    const char* method = m < kMethods - 1 ? kMethodNames[m] : "other";
    for (int c = 0; c < kStatusCodes; ++c) {
      rpcs_[m][c] = &rpcs.Add({{"method", method}, {"code", CanonicalStatusCodeName(c)}});
    }
  }
  auto& refused = BuildCounter()
                      .Name("deformd_refused_total")
                      .Help("Refused calls and connections, logged or not, by reason")
                      .Register(*registry_);
  for (int r = 0; r < kRefusals; ++r) {
    refused_[r] = &refused.Add({{"reason", RefusalName(static_cast<Refusal>(r))}});
  }
  auto& started = BuildCounter()
                      .Name("grpc_server_started_total")
                      .Help("Total number of RPCs started on the server.")
                      .Register(*registry_);
  auto& handled = BuildCounter()
                      .Name("grpc_server_handled_total")
                      .Help(
                          "Total number of RPCs completed on the server, regardless of success "
                          "or failure.")
                      .Register(*registry_);
  auto& received = BuildCounter()
                       .Name("grpc_server_msg_received_total")
                       .Help("Total number of RPC stream messages received on the server.")
                       .Register(*registry_);
  auto& sent = BuildCounter()
                   .Name("grpc_server_msg_sent_total")
                   .Help("Total number of gRPC stream messages sent by the server.")
                   .Register(*registry_);
  auto& handling = BuildHistogram()
                       .Name("grpc_server_handling_seconds")
                       .Help(
                           "Histogram of response latency (seconds) of gRPC that had been "
                           "application-level handled by the server.")
                       .Register(*registry_);
  // Unary calls take milliseconds; streams last a session (minutes to an hour or more).
  const prometheus::Histogram::BucketBoundaries handling_bounds = {
      0.0005, 0.001, 0.0025, 0.005, 0.01, 0.025, 0.05, 0.1, 0.25, 0.5,
      1,      2.5,   5,      10,    30,   60,    300,  900, 3600};
  for (int m = 0; m < kGrpcMethods; ++m) {
    const GrpcMethod& row = kServedGrpcMethods[m];
    const prometheus::Labels labels = {{"grpc_type", GrpcTypeName(row.type)},
                                       {"grpc_service", std::string(row.service)},
                                       {"grpc_method", std::string(row.method)}};
    GrpcSeries& series = grpc_[m];
    series.started = &started.Add(labels);
    series.received = &received.Add(labels);
    series.sent = &sent.Add(labels);
    series.handling_seconds = &handling.Add(labels, handling_bounds);
    for (int c = 0; c < kStatusCodes; ++c) {
      prometheus::Labels with_code = labels;
      with_code.emplace("grpc_code", CanonicalStatusCodeName(c));
      series.handled[c] = &handled.Add(with_code);
    }
  }
  auto& builds = BuildHistogram()
                     .Name("deformd_build_seconds")
                     .Help("Mesh builds (LoadMesh, --preload, --store), by result")
                     .Register(*registry_);
  const auto build_bounds = Exponential(0.01, 2, 16);  // 10 ms .. 5.5 min
  build_ok_seconds_ = &builds.Add({{"result", "ok"}}, build_bounds);
  build_error_seconds_ = &builds.Add({{"result", "error"}}, build_bounds);
  refactorization_seconds_ = &BuildHistogram()
                                  .Name("deformd_refactorization_seconds")
                                  .Help("Stiffness refactorizations of Deform streams")
                                  .Register(*registry_)
                                  .Add({}, Exponential(0.001, 2, 14));
  const auto gauge = [this](const char* name, const char* help) {
    return &BuildGauge().Name(name).Help(help).Register(*registry_).Add({});
  };
  streams_open_ = gauge("deformd_streams_open", "Open Deform streams");
  meshes_loaded_ = gauge("deformd_meshes_loaded", "Meshes loaded");
  loads_in_progress_ = gauge("deformd_loads_in_progress", "Mesh loads in progress");
  memory_used_ = gauge("deformd_memory_budget_used_bytes",
                       "Memory budget used by loaded meshes and unloaded ones still streamed");
  memory_reserved_ =
      gauge("deformd_memory_budget_reserved_bytes", "Memory budget held by loads in progress");
  memory_streams_ = gauge("deformd_memory_budget_streams_bytes",
                          "Memory budget held by streams' buffers and own factorizations");
  memory_budget_ = gauge("deformd_memory_budget_bytes", "The memory budget (--max-memory-mb)");
  notice_backlog_ =
      gauge("deformd_notice_backlog_bytes", "Serialized bytes of notices waiting unwritten");
  BuildGauge()
      .Name("deformd_build_info")
      .Help("The build's version and commit, as --version prints them (value 1)")
      .Register(*registry_)
      .Add({{"version", std::string(BuildVersion())}, {"commit", std::string(BuildCommit())}})
      .Set(1);
}

ServiceMetrics::~ServiceMetrics() = default;

const char* ServiceMetrics::RefusalName(Refusal reason) {
  switch (reason) {
    case Refusal::kUnauthenticated:
      return "unauthenticated";
    case Refusal::kHttpConnectionLimit:
      return "http_connection_limit";
    case Refusal::kHttpHostOrOrigin:
      return "http_host_or_origin";
    case Refusal::kHttpTooLarge:
      return "http_too_large";
    case Refusal::kMetricsScrape:
      return "metrics_scrape";
    case Refusal::kGrpcConnectionLimit:
      return "grpc_connection_limit";
    case Refusal::kNoDescriptors:
      return "no_descriptors";
  }
  return "other";
}

void ServiceMetrics::Refused(Refusal reason) {
  const int index = static_cast<int>(reason);
  if (index >= 0 && index < kRefusals) refused_[index]->Increment();
}

void ServiceMetrics::FrameWritten(int encoding, std::size_t bytes, double queue_seconds,
                                  double compute_seconds, std::uint64_t skipped_poses) {
  if (encoding < 0 || encoding >= kEncodings) encoding = 1;
  frames_sent_[encoding]->Increment();
  frame_bytes_sent_[encoding]->Increment(static_cast<double>(bytes));
  frame_server_seconds_.Observe(queue_seconds + compute_seconds);
  frame_queue_seconds_.Observe(queue_seconds);
  frame_compute_seconds_.Observe(compute_seconds);
  if (skipped_poses > 0) poses_skipped_->Increment(static_cast<double>(skipped_poses));
}

void ServiceMetrics::ConstrainedFrameWritten(double constraint_seconds, bool unresolved) {
  frame_constraint_seconds_.Observe(constraint_seconds);
  if (unresolved) frames_unresolved_->Increment();
}

void ServiceMetrics::NoticeWritten(int kind) {
  if (kind <= 0 || kind >= kNoticeKinds) return;
  notices_sent_[kind]->Increment();
}

void ServiceMetrics::RpcFinished(std::string_view method, int code) {
  if (code < 0 || code >= kStatusCodes) code = 2;  // UNKNOWN
  rpcs_[MethodIndex(method)][code]->Increment();
}

void ServiceMetrics::GrpcStarted(int grpc_method) {
  if (grpc_method >= 0 && grpc_method < kGrpcMethods) grpc_[grpc_method].started->Increment();
}

void ServiceMetrics::GrpcMessageReceived(int grpc_method) {
  if (grpc_method >= 0 && grpc_method < kGrpcMethods) grpc_[grpc_method].received->Increment();
}

void ServiceMetrics::GrpcMessageSent(int grpc_method) {
  if (grpc_method >= 0 && grpc_method < kGrpcMethods) grpc_[grpc_method].sent->Increment();
}

void ServiceMetrics::GrpcHandled(int grpc_method, int code, double seconds) {
  if (grpc_method < 0 || grpc_method >= kGrpcMethods) return;
  if (code < 0 || code >= kStatusCodes) code = 2;  // UNKNOWN
  grpc_[grpc_method].handled[code]->Increment();
  grpc_[grpc_method].handling_seconds->Observe(seconds);
}

void ServiceMetrics::BuildFinished(double seconds, bool ok) {
  (ok ? build_ok_seconds_ : build_error_seconds_)->Observe(seconds);
}

void ServiceMetrics::RefactorizationFinished(double seconds) {
  refactorization_seconds_->Observe(seconds);
}

void ServiceMetrics::SetCertificateExpiry(std::int64_t not_after_unix_seconds) {
  if (certificate_expiry_ == nullptr) {
    certificate_expiry_ = &prometheus::BuildGauge()
                               .Name("deformd_tls_certificate_expiry_seconds")
                               .Help("The served TLS certificate's end of validity, Unix seconds")
                               .Register(*registry_)
                               .Add({});
  }
  certificate_expiry_->Set(static_cast<double>(not_after_unix_seconds));
}

void ServiceMetrics::SetGauges(const Gauges& gauges) {
  streams_open_->Set(gauges.streams_open);
  meshes_loaded_->Set(gauges.meshes_loaded);
  loads_in_progress_->Set(gauges.loads_in_progress);
  memory_used_->Set(static_cast<double>(gauges.memory_used_bytes));
  memory_reserved_->Set(static_cast<double>(gauges.memory_reserved_bytes));
  memory_streams_->Set(static_cast<double>(gauges.memory_streams_bytes));
  memory_budget_->Set(static_cast<double>(gauges.memory_budget_bytes));
  notice_backlog_->Set(static_cast<double>(gauges.notice_backlog_bytes));
  MutexLock lock(&mesh_streams_mutex_);
  mesh_streams_ = gauges.mesh_streams;
}

std::string ServiceMetrics::Serialize() const {
  std::vector<prometheus::MetricFamily> families = registry_->Collect();
  for (const AtomicHistogram* histogram : {&frame_server_seconds_, &frame_queue_seconds_,
                                           &frame_compute_seconds_, &frame_constraint_seconds_}) {
    families.push_back(histogram->Collect());
  }
  {
    prometheus::MetricFamily mesh_streams{"deformd_mesh_streams_open",
                                          "Open Deform streams of each loaded mesh",
                                          prometheus::MetricType::Gauge,
                                          {}};
    MutexLock lock(&mesh_streams_mutex_);
    for (const auto& [mesh, streams] : mesh_streams_) {
      prometheus::ClientMetric& metric = mesh_streams.metric.emplace_back();
      metric.label.push_back({"mesh", mesh});
      metric.gauge.value = streams;
    }
    families.push_back(std::move(mesh_streams));
  }
  std::vector<prometheus::MetricFamily> process = process_->Collect();
  families.insert(families.end(), std::make_move_iterator(process.begin()),
                  std::make_move_iterator(process.end()));
  return prometheus::TextSerializer().Serialize(families);
}

}  // namespace deform::service
