// Refusals any peer can cause at will are counted, every one, in deformd_refused_total, and
// logged within ServiceContext's budget of lines: a client hammering the server with a bad token,
// or the HTTP port with another Host, cannot fill the disk. The line after a quiet second says
// how many were held back, so the counts in the log add up.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <chrono>
#include <cstdint>
#include <regex>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "service/context/service_context.h"
#include "tests/service/support/log_capture.h"
#include "tests/service/support/raw_http.h"
#include "tests/service/support/temp_dir.h"
#include "tests/service/support/test_server.h"
#include "tests/service/support/token_file.h"

namespace deform::test_support {
namespace {

using ::testing::HasSubstr;

constexpr int kBurst = static_cast<int>(service::ServiceContext::kRefusalLineBurst);

// The lines of `log` holding `marker`, and the sum of their "(and N more like it" notes.
struct Lines {
  int count = 0;
  std::uint64_t held_back = 0;
};
Lines LinesWith(const std::string& log, const std::string& marker) {
  Lines lines;
  std::istringstream in(log);
  const std::regex note(R"(\(and ([0-9]+) more like it, not logged\))");
  for (std::string line; std::getline(in, line);) {
    if (line.find(marker) == std::string::npos) continue;
    ++lines.count;
    std::smatch match;
    if (std::regex_search(line, match, note)) lines.held_back += std::stoull(match[1]);
  }
  return lines;
}

std::string MetricLine(TestServer& server, const std::string& reason) {
  const std::string page = server.server().context().metrics().Serialize();
  const std::string name = "deformd_refused_total{reason=\"" + reason + "\"} ";
  const std::size_t at = page.find(name);
  return at == std::string::npos ? "" : page.substr(at, page.find('\n', at) - at);
}

TEST(RefusalLogTest, UnauthenticatedCallsAreAllCountedAndLoggedWithinTheBudget) {
  TempDir dir;
  TestServer server(TestServerOptions(), dir.Write("tokens", TokenLine("good", "ward", "tenant")));
  auto good = server.NewClient(WithToken("good"));
  std::vector<v1::MeshSummary> meshes;
  ASSERT_TRUE(good->ListMeshes(&meshes).ok());  // the audit logger exists from here
  auto bad = server.NewClient(WithToken("bad"));
  LogCapture capture;
  constexpr int kCalls = 200;
  const auto start = std::chrono::steady_clock::now();
  for (int i = 0; i < kCalls; ++i) {
    ASSERT_EQ(bad->ListMeshes(&meshes).error_code(), grpc::StatusCode::UNAUTHENTICATED);
  }
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  // After a quiet second and a half, one more line, which reports what was held back.
  std::this_thread::sleep_for(std::chrono::milliseconds(1500));
  ASSERT_EQ(bad->ListMeshes(&meshes).error_code(), grpc::StatusCode::UNAUTHENTICATED);
  const std::string log = capture.Stop();
  const Lines lines = LinesWith(log, "tenant=- action=list");
  EXPECT_GE(lines.count, kBurst + 1);
  EXPECT_LE(lines.count, kBurst + 2 + static_cast<int>(seconds)) << log;
  EXPECT_GT(lines.held_back, 0u) << log;
  EXPECT_EQ(lines.count + lines.held_back, kCalls + 1u) << log;
  EXPECT_EQ(MetricLine(server, "unauthenticated"),
            "deformd_refused_total{reason=\"unauthenticated\"} " + std::to_string(kCalls + 1));
}

TEST(RefusalLogTest, RequestsForAnotherHostAreAllCountedAndLoggedWithinTheBudget) {
  TestServer server(TestServerOptions(), "", true);
  {
    auto client = server.NewClient();
    std::vector<v1::MeshSummary> meshes;
    ASSERT_TRUE(client->ListMeshes(&meshes).ok());
  }
  LogCapture capture;
  constexpr int kRequests = 30;
  for (int i = 0; i < kRequests; ++i) {
    const RawHttpResponse response = RawHttpExchange(
        server.web_port(), "GET / HTTP/1.1\r\nHost: rebind.attacker.example\r\n\r\n");
    ASSERT_EQ(response.status, 403) << i;
  }
  const std::string log = capture.Stop();
  const Lines lines = LinesWith(log, "request refused: Host 'rebind.attacker.example'");
  EXPECT_GE(lines.count, kBurst);
  EXPECT_LT(lines.count, kRequests) << log;
  EXPECT_EQ(MetricLine(server, "http_host_or_origin"),
            "deformd_refused_total{reason=\"http_host_or_origin\"} " + std::to_string(kRequests));
}

TEST(RefusalLogTest, RefusedScrapesAreAllCountedAndLoggedWithinTheBudget) {
  TempDir dir;
  service::ServerOptions options = TestServerOptions();
  options.metrics_address = "127.0.0.1:0";
  TestServer server(options, dir.Write("tokens", TokenLine("good", "ward", "tenant") +
                                                     TokenLine("scrape", "prometheus", "metrics")));
  const int port = server.server().metrics_port();
  const std::string host = "Host: 127.0.0.1:" + std::to_string(port) + "\r\n";
  LogCapture capture;
  constexpr int kScrapes = 30;
  for (int i = 0; i < kScrapes; ++i) {
    // A bad token (401) and a tenant's (403) alternately: both are any peer's to repeat.
    const std::string token = i % 2 == 0 ? "bad" : "good";
    const RawHttpResponse response =
        RawHttpExchange(port, "GET /metrics HTTP/1.1\r\n" + host + "Authorization: Bearer " +
                                  token + "\r\nConnection: close\r\n\r\n");
    ASSERT_EQ(response.status, i % 2 == 0 ? 401 : 403) << i;
  }
  const RawHttpResponse scrape =
      RawHttpExchange(port, "GET /metrics HTTP/1.1\r\n" + host +
                                "Authorization: Bearer scrape\r\nConnection: close\r\n\r\n");
  ASSERT_EQ(scrape.status, 200) << scrape.head;
  const std::string log = capture.Stop();
  const Lines lines = LinesWith(log, "metrics: scrape");
  EXPECT_GE(lines.count, kBurst);
  EXPECT_LT(lines.count, kScrapes) << log;
  EXPECT_THAT(scrape.body, HasSubstr("deformd_refused_total{reason=\"metrics_scrape\"} " +
                                     std::to_string(kScrapes)));
}

}  // namespace
}  // namespace deform::test_support
