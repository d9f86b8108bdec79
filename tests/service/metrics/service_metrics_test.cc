// ServiceMetrics' frame split and standard gRPC series, through the page a scrape gets: every
// gRPC series exists before any call, and the calls land in their method's series.
#include "service/metrics/service_metrics.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cstdlib>
#include <sstream>
#include <string>

namespace deform::service {
namespace {

using ::testing::HasSubstr;

// The value of the series written exactly `series` in `page`; -1 when absent.
double Value(const std::string& page, const std::string& series) {
  std::istringstream lines(page);
  std::string line;
  while (std::getline(lines, line)) {
    if (line.rfind(series + " ", 0) == 0) {
      return std::strtod(line.c_str() + series.size() + 1, nullptr);
    }
  }
  return -1;
}

constexpr const char* kDeformLabels =
    "grpc_method=\"Deform\",grpc_service=\"deform.v1.DeformService\",grpc_type=\"bidi_stream\"";

TEST(ServiceMetricsTest, FrameServerTimeIsItsQueueAndComputeTimes) {
  ServiceMetrics metrics;
  metrics.FrameWritten(1, 1000, 0.004, 0.001, 0);
  metrics.FrameWritten(1, 1000, 0.0, 0.002, 3);
  const std::string page = metrics.Serialize();
  EXPECT_EQ(Value(page, "deformd_frame_queue_seconds_count"), 2);
  EXPECT_DOUBLE_EQ(Value(page, "deformd_frame_queue_seconds_sum"), 0.004);
  EXPECT_EQ(Value(page, "deformd_frame_compute_seconds_count"), 2);
  EXPECT_DOUBLE_EQ(Value(page, "deformd_frame_compute_seconds_sum"), 0.003);
  EXPECT_DOUBLE_EQ(Value(page, "deformd_frame_server_seconds_sum"), 0.007);
  // 4 ms of queue lies above the 2 ms bucket, below the 4 ms one.
  EXPECT_EQ(Value(page, "deformd_frame_queue_seconds_bucket{le=\"0.002\"}"), 1);
  EXPECT_EQ(Value(page, "deformd_frame_queue_seconds_bucket{le=\"0.004\"}"), 2);
  EXPECT_EQ(Value(page, "deformd_poses_skipped_total"), 3);
}

TEST(ServiceMetricsTest, EveryServedMethodHasItsSeriesBeforeAnyCall) {
  ServiceMetrics metrics;
  const std::string page = metrics.Serialize();
  for (const GrpcMethod& row : kServedGrpcMethods) {
    const std::string labels = "grpc_method=\"" + std::string(row.method) + "\",grpc_service=\"" +
                               std::string(row.service) + "\",grpc_type=\"" +
                               GrpcTypeName(row.type) + "\"";
    EXPECT_EQ(Value(page, "grpc_server_started_total{" + labels + "}"), 0) << labels;
    EXPECT_EQ(Value(page, "grpc_server_msg_sent_total{" + labels + "}"), 0) << labels;
    EXPECT_EQ(Value(page, "grpc_server_handling_seconds_count{" + labels + "}"), 0) << labels;
    EXPECT_EQ(Value(page, "grpc_server_handled_total{grpc_code=\"OK\"," + labels + "}"), 0);
    EXPECT_EQ(
        Value(page, "grpc_server_handled_total{grpc_code=\"UNAUTHENTICATED\"," + labels + "}"), 0);
  }
}

TEST(ServiceMetricsTest, CallsLandInTheirMethodsSeries) {
  ServiceMetrics metrics;
  const int deform = ServedGrpcMethodIndex("/deform.v1.DeformService/Deform");
  ASSERT_GE(deform, 0);
  metrics.GrpcStarted(deform);
  metrics.GrpcStarted(deform);
  metrics.GrpcMessageReceived(deform);
  metrics.GrpcMessageSent(deform);
  metrics.GrpcMessageSent(deform);
  metrics.GrpcHandled(deform, 0, 12.0);
  metrics.GrpcHandled(deform, 14, 0.5);    // UNAVAILABLE
  metrics.GrpcHandled(deform, 99, 0.001);  // out of range: UNKNOWN
  metrics.GrpcStarted(-1);                 // not a served method: ignored
  metrics.GrpcHandled(-1, 0, 1.0);
  const std::string page = metrics.Serialize();
  const std::string labels = std::string("{") + kDeformLabels + "}";
  EXPECT_EQ(Value(page, "grpc_server_started_total" + labels), 2);
  EXPECT_EQ(Value(page, "grpc_server_msg_received_total" + labels), 1);
  EXPECT_EQ(Value(page, "grpc_server_msg_sent_total" + labels), 2);
  EXPECT_EQ(
      Value(page, std::string("grpc_server_handled_total{grpc_code=\"OK\",") + kDeformLabels + "}"),
      1);
  EXPECT_EQ(Value(page, std::string("grpc_server_handled_total{grpc_code=\"UNAVAILABLE\",") +
                            kDeformLabels + "}"),
            1);
  EXPECT_EQ(Value(page, std::string("grpc_server_handled_total{grpc_code=\"UNKNOWN\",") +
                            kDeformLabels + "}"),
            1);
  EXPECT_EQ(Value(page, "grpc_server_handling_seconds_count" + labels), 3);
  EXPECT_EQ(Value(page, std::string("grpc_server_handling_seconds_bucket{") + kDeformLabels +
                            ",le=\"10\"}"),
            2);
  EXPECT_THAT(page, HasSubstr("# TYPE grpc_server_handling_seconds histogram"));
}

}  // namespace
}  // namespace deform::service
