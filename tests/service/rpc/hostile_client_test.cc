// Hostile and careless clients against the real server: one test per defect found when the service
// was probed that way. In-process servers where the server's own counters are needed (the notice
// backlog), the real deformd executable where only a process shows the defect (binding, the
// linked health descriptor, SIGTERM). Every test also checks that the server keeps serving.
#include <arpa/inet.h>
#include <gmock/gmock.h>
#include <google/protobuf/descriptor.pb.h>
#include <google/protobuf/unknown_field_set.h>
#include <grpcpp/generic/generic_stub.h>
#include <grpcpp/grpcpp.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <fstream>
#include <limits>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "deform_client.h"
#include "service/base/open_files_limit.h"
#include "service/context/service_context.h"
#include "service/deform/deform_outbox.h"
#include "tests/service/support/deformd_process.h"
#include "tests/service/support/service_fixture.h"
#include "tests/service/support/stream_recorder.h"

namespace deform::test_support {
namespace {

using ::testing::HasSubstr;
using Clock = std::chrono::steady_clock;

double SecondsSince(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

class HostileClientTest : public ServiceTest {
 protected:
  // Sends `pose` on a fresh stream on `mesh_id`; the notice or frame that answers it.
  v1::DeformResponse AnswerTo(const std::string& mesh_id, const v1::PoseUpdate& pose) {
    StreamRecorder recorder;
    auto stream = client_->OpenStream(mesh_id, recorder.Callbacks());
    EXPECT_TRUE(stream->SendPose(pose));
    v1::DeformResponse answer;
    EXPECT_TRUE(recorder.WaitUntil([&] {
      for (const RecordedEvent& event : recorder.EventsLocked()) {
        if (event.is_frame) {
          *answer.mutable_frame() = event.frame;
          return true;
        }
        if (event.notice.kind() == v1::Notice::KIND_POSE_REJECTED) {
          *answer.mutable_notice() = event.notice;
          return true;
        }
      }
      return false;
    })) << "no answer to the pose";
    stream->Close();
    stream->Wait();
    return answer;
  }
};

// Names, ids, joint and axis strings over their limits are INVALID_ARGUMENT naming the field and
// the limit, and are never echoed.
TEST_F(HostileClientTest, OversizedStringsAreRefusedNamingTheFieldAndTheLimit) {
  StartServer();
  const std::string mesh_id = LoadPhantom(300);

  v1::MeshSummary summary;
  const grpc::Status long_name = client_->LoadPhantom(300, {}, &summary, {}, std::string(300, 'n'));
  EXPECT_EQ(long_name.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_THAT(long_name.error_message(), HasSubstr("name is 300 bytes long"));
  EXPECT_THAT(long_name.error_message(), HasSubstr("limit of 256 bytes"));

  const grpc::Status long_id = client_->UnloadMesh(std::string(200, 'i'));
  EXPECT_EQ(long_id.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_THAT(long_id.error_message(), HasSubstr("mesh_id is 200 bytes long"));

  v1::PoseUpdate pose = KneePose(1, 30);
  pose.mutable_angles(0)->set_joint(std::string(1 << 20, 'j'));
  v1::DeformResponse answer = AnswerTo(mesh_id, pose);
  ASSERT_TRUE(answer.has_notice());
  EXPECT_THAT(answer.notice().message(), HasSubstr("angles[0].joint is 1048576 bytes long"));
  EXPECT_LT(answer.notice().message().size(), 200u);

  pose = KneePose(2, 30);
  pose.mutable_angles(0)->set_axis(std::string(100, 'a'));
  answer = AnswerTo(mesh_id, pose);
  ASSERT_TRUE(answer.has_notice());
  EXPECT_THAT(answer.notice().message(), HasSubstr("angles[0].axis is 100 bytes long"));

  StreamRecorder recorder;
  auto stream = client_->OpenStream(mesh_id, recorder.Callbacks());
  v1::StiffnessUpdate stiffness;
  v1::JointMaterialUpdate* material = stiffness.add_joint_materials();
  material->set_joint(std::string(5000, 'k'));
  material->mutable_material()->set_soft(2);
  ASSERT_TRUE(stream->SendStiffness(stiffness));
  ASSERT_TRUE(recorder.WaitForNotice(v1::Notice::KIND_STIFFNESS_REJECTED));
  EXPECT_THAT(recorder.FindNotice(v1::Notice::KIND_STIFFNESS_REJECTED)->message(),
              HasSubstr("joint_materials[0].joint is 5000 bytes long"));
  stream->Close();
  EXPECT_TRUE(stream->Wait().ok());
  ExpectBackgroundStreamAlive();
}

// A 16 KB unknown id used to be echoed whole into the status, past gRPC's metadata limit.
TEST_F(HostileClientTest, SixteenKilobyteUnknownIdGetsAShortInvalidArgument) {
  StartServer();
  const std::string id(16 << 10, 'x');
  v1::GetMeshInfoResponse info;
  const grpc::Status get = client_->GetMeshInfo(id, false, &info);
  EXPECT_EQ(get.error_code(), grpc::StatusCode::INVALID_ARGUMENT) << get.error_message();
  EXPECT_LT(get.error_message().size(), 200u);
  const grpc::Status unload = client_->UnloadMesh(id);
  EXPECT_EQ(unload.error_code(), grpc::StatusCode::INVALID_ARGUMENT) << unload.error_message();
  StreamRecorder recorder;
  auto stream = client_->OpenStream(id, recorder.Callbacks());
  const grpc::Status streamed = stream->Wait();
  EXPECT_EQ(streamed.error_code(), grpc::StatusCode::INVALID_ARGUMENT) << streamed.error_message();
  EXPECT_THAT(streamed.error_message(), HasSubstr("start.mesh_id is 16384 bytes long"));
  ExpectBackgroundStreamAlive();
}

// A client that sends rejected poses and rejected stiffness updates as fast as it can and never
// reads: the server's unwritten notices stay within their byte bound (the server's own gauge,
// not RSS). The client is a raw gRPC stream: the client library always reads.
TEST_F(HostileClientTest, NoticeFloodFromAClientThatDoesNotReadStaysBounded) {
  StartServer();
  const std::string mesh_id = LoadPhantom(300);
  auto channel = grpc::CreateChannel(server_->target(), grpc::InsecureChannelCredentials());
  auto stub = v1::DeformService::NewStub(channel);
  grpc::ClientContext context;
  auto stream = stub->Deform(&context);
  v1::DeformRequest start;
  start.mutable_start()->set_mesh_id(mesh_id);
  ASSERT_TRUE(stream->Write(start));

  std::atomic<int> sent{0};
  std::atomic<bool> stop{false};
  std::thread writer([&] {
    const std::string joint(250, 'q');  // within the limit: echoed (cut) in every rejection
    for (int k = 0; k < 40000 && !stop; ++k) {
      v1::DeformRequest request;
      if (k % 2 == 0) {
        v1::JointAngle* angle = request.mutable_pose()->add_angles();
        angle->set_joint(joint);
        angle->set_axis("x");
        request.mutable_pose()->set_sequence(static_cast<std::uint64_t>(k));
      } else {
        v1::RegionWeight* weight = request.mutable_stiffness()->add_region_weights();
        weight->set_joint(joint);
        weight->set_weight(2);
      }
      if (!stream->Write(request)) break;
      ++sent;
    }
  });
  std::atomic<std::int64_t>& gauge = server_->server().context().notice_backlog_bytes();
  std::int64_t peak = 0;
  const Clock::time_point start_time = Clock::now();
  while (SecondsSince(start_time) < 4 && sent < 40000) {
    peak = std::max<std::int64_t>(peak, gauge.load());
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  peak = std::max<std::int64_t>(peak, gauge.load());
  std::printf("notice flood: %d requests sent in %.1f s, peak unwritten notice bytes %lld\n",
              sent.load(), SecondsSince(start_time), static_cast<long long>(peak));
  // The client really flooded: far more rejections than the bound holds.
  EXPECT_GT(static_cast<std::size_t>(sent.load()) * 250,
            4 * service::DeformOutbox::kMaxNoticeBacklogBytes);
  EXPECT_GT(peak, 0);
  EXPECT_LE(static_cast<std::size_t>(peak), service::DeformOutbox::kMaxNoticeBacklogBytes +
                                                2 * service::DeformOutbox::kMaxNoticeMessageBytes);
  stop = true;
  context.TryCancel();
  writer.join();
  stream->Finish();
  ExpectBackgroundStreamAlive();
}

// Quaternion components of 1e155 used to become the rest pose, angles of 1e308 degrees were
// accepted: both are rejected with a notice and the stream goes on.
TEST_F(HostileClientTest, AbsurdQuaternionsAndAnglesAreRejectedWithANotice) {
  StartServer();
  const std::string mesh_id = LoadPhantom(300);

  v1::PoseUpdate rotation;
  v1::JointRotation* q = rotation.add_rotations();
  q->set_joint("knee");
  q->set_w(1e155);
  q->set_x(1e155);
  v1::DeformResponse answer = AnswerTo(mesh_id, rotation);
  ASSERT_TRUE(answer.has_notice()) << "a 1e155 quaternion gave a frame";
  EXPECT_THAT(answer.notice().message(), HasSubstr("has norm 1.41421e+155"));

  v1::PoseUpdate root;
  root.mutable_root()->mutable_rotation()->set_w(3);
  answer = AnswerTo(mesh_id, root);
  ASSERT_TRUE(answer.has_notice()) << "a root quaternion of norm 3 gave a frame";
  EXPECT_THAT(answer.notice().message(), HasSubstr("root rotation has norm 3"));

  v1::PoseUpdate angle = KneePose(1, 1e308);
  answer = AnswerTo(mesh_id, angle);
  ASSERT_TRUE(answer.has_notice()) << "an angle of 1e308 degrees gave a frame";
  EXPECT_THAT(answer.notice().message(), HasSubstr("beyond the limit of +-36000 degrees"));

  answer = AnswerTo(mesh_id, KneePose(7, 45));
  EXPECT_TRUE(answer.has_frame());
  ExpectBackgroundStreamAlive();
}

// A declared upload size of 2^64-1 used to overflow the sum and be reported as "193 bytes".
TEST_F(HostileClientTest, DeclaredUploadOfTwoToTheSixtyFourIsRefusedWithTheRealFigure) {
  StartServer();
  auto stub = v1::DeformService::NewStub(
      grpc::CreateChannel(server_->target(), grpc::InsecureChannelCredentials()));
  grpc::ClientContext context;
  auto stream = stub->LoadMesh(&context);
  v1::LoadMeshRequest request;
  v1::UploadSource* upload = request.mutable_header()->mutable_upload();
  upload->set_format(v1::MESH_FORMAT_OBJ);
  upload->set_mesh_size_bytes(std::numeric_limits<std::uint64_t>::max());
  upload->set_skeleton(std::string(193, 's'));
  upload->set_skeleton_format(v1::SKELETON_FORMAT_TGF);
  ASSERT_TRUE(stream->Write(request));
  stream->WritesDone();
  v1::LoadMeshResponse response;
  while (stream->Read(&response)) {
  }
  const grpc::Status status = stream->Finish();
  EXPECT_EQ(status.error_code(), grpc::StatusCode::RESOURCE_EXHAUSTED);
  EXPECT_THAT(status.error_message(), HasSubstr("mesh 18446744073709551615"));
  EXPECT_THAT(status.error_message(), HasSubstr("more than 18446744073709551615 bytes"));
  ExpectBackgroundStreamAlive();
}

// A connection that never answers the server's keepalive pings is closed; a connection without
// calls is closed after the idle limit. (gRPC's defaults: pings after 2 hours, no idle limit.)
TEST_F(HostileClientTest, SilentConnectionsAreClosedByKeepaliveAndIdleLimits) {
  service::ServerOptions options = TestServerOptions();
  options.connections.keepalive_time_ms = 300;
  options.connections.keepalive_timeout_ms = 300;
  options.connections.max_connection_idle_ms = 3'600'000;
  StartServer(options);

  // A raw TCP peer: the HTTP/2 preface and an empty SETTINGS frame, then silence.
  const int fd = socket(AF_INET, SOCK_STREAM, 0);
  ASSERT_GE(fd, 0);
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_port = htons(static_cast<std::uint16_t>(server_->server().port()));
  inet_pton(AF_INET, "127.0.0.1", &address.sin_addr);
  ASSERT_EQ(connect(fd, reinterpret_cast<sockaddr*>(&address), sizeof address), 0);
  const std::string hello =
      std::string("PRI * HTTP/2.0\r\n\r\nSM\r\n\r\n") + std::string("\0\0\0\x04\0\0\0\0\0", 9);
  ASSERT_EQ(send(fd, hello.data(), hello.size(), 0), static_cast<ssize_t>(hello.size()));
  timeval timeout{10, 0};
  setsockopt(fd, SOL_SOCKET, SO_RCVTIMEO, &timeout, sizeof timeout);
  const Clock::time_point start = Clock::now();
  char buffer[4096];
  ssize_t got = 0;
  while ((got = recv(fd, buffer, sizeof buffer, 0)) > 0) {
  }
  close(fd);
  EXPECT_EQ(got, 0) << "the silent connection was not closed within 10 s";
  EXPECT_LT(SecondsSince(start), 5.0);
  std::printf("silent connection closed after %.2f s (keepalive 0.3 s + 0.3 s)\n",
              SecondsSince(start));

  // Idle limit: a connected client channel goes back to IDLE once the server closes it.
  service::ServerOptions idle_options = TestServerOptions();
  idle_options.connections.max_connection_idle_ms = 500;
  TestServer idle_server(idle_options);
  auto channel = grpc::CreateChannel(idle_server.target(), grpc::InsecureChannelCredentials());
  client::DeformClient idle_client(channel);
  ASSERT_TRUE(idle_client.WaitForReady(10'000));
  std::vector<v1::MeshSummary> meshes;
  ASSERT_TRUE(idle_client.ListMeshes(&meshes).ok());
  const Clock::time_point idle_start = Clock::now();
  while (channel->GetState(false) == GRPC_CHANNEL_READY && SecondsSince(idle_start) < 10) {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  EXPECT_NE(channel->GetState(false), GRPC_CHANNEL_READY)
      << "the idle connection was still open after 10 s";
  std::printf("idle connection closed after %.2f s (limit 0.5 s)\n", SecondsSince(idle_start));
  ExpectBackgroundStreamAlive();
}

// gRPC turns SO_REUSEPORT on by default: a second server on a taken address started and took half
// the connections. It must exit non-zero with a clear line instead.
// Each connection takes a descriptor at its accept, so a server left at a low soft limit (the
// common 1,024; here 256) refuses connections with EMFILE long before its hard limit: deformd
// raises its soft limit to the hard one at start, and says so.
TEST(HostileDeployment, TheOpenFilesSoftLimitIsRaisedToTheHardOneAtStart) {
  rlimit own{};
  ASSERT_EQ(getrlimit(RLIMIT_NOFILE, &own), 0);
  ASSERT_TRUE(own.rlim_max == RLIM_INFINITY || own.rlim_max > 256)
      << "the hard limit on open files is " << own.rlim_max << ": nothing to raise to";
  rlimit low = own;
  low.rlim_cur = 256;
  ASSERT_EQ(setrlimit(RLIMIT_NOFILE, &low), 0);
  DeformdProcess server({"--listen", "127.0.0.1:0", "--workers", "1"});  // inherits 256
  ASSERT_EQ(setrlimit(RLIMIT_NOFILE, &own), 0);
  ASSERT_GT(server.WaitForListeningPort(), 0) << server.output();
  std::ifstream limits("/proc/" + std::to_string(server.pid()) + "/limits");
  std::string line, soft;
  while (std::getline(limits, line)) {
    if (line.rfind("Max open files", 0) != 0) continue;
    std::istringstream fields(line.substr(std::string("Max open files").size()));
    fields >> soft;
  }
  const std::uint64_t expected = own.rlim_max == RLIM_INFINITY
                                     ? service::kMaxOpenFiles
                                     : static_cast<std::uint64_t>(own.rlim_max);
  EXPECT_EQ(soft, std::to_string(expected));
  EXPECT_THAT(server.output(),
              HasSubstr("open files: soft limit raised from 256 to " + std::to_string(expected)));
  server.Signal(SIGTERM);
  EXPECT_EQ(server.Wait(std::chrono::seconds(10)), std::optional<int>(0));
}

TEST(HostileDeployment, SecondServerOnATakenAddressExitsNonZero) {
  DeformdProcess first({"--listen", "127.0.0.1:0", "--workers", "1"});
  const int port = first.WaitForListeningPort();
  ASSERT_GT(port, 0) << first.output();
  DeformdProcess second({"--listen", "127.0.0.1:" + std::to_string(port), "--workers", "1"});
  const std::optional<int> code = second.Wait(std::chrono::seconds(30));
  ASSERT_TRUE(code.has_value()) << "the second server is still running: " << second.output();
  EXPECT_NE(*code, 0);
  EXPECT_THAT(second.output(), HasSubstr("cannot listen on '127.0.0.1:" + std::to_string(port)));
  EXPECT_TRUE(first.running());
  first.Signal(SIGTERM);
  EXPECT_EQ(first.Wait(std::chrono::seconds(10)), std::optional<int>(0));
}

// A second deformd on the same port in the other loopback family (or on `localhost`) took the
// clients that dial localhost:P: every pairing is refused, naming the address, exit code 1.
TEST(HostileDeployment, OneServerPerPortOnEveryLoopbackFamily) {
  for (const std::string first_host : {"127.0.0.1", "[::1]"}) {
    SCOPED_TRACE("first on " + first_host);
    DeformdProcess first({"--listen", first_host + ":0", "--workers", "1"});
    const int port = first.WaitForListeningPort();
    ASSERT_GT(port, 0) << first.output();
    for (const std::string second_host : {"127.0.0.1", "[::1]", "localhost"}) {
      const std::string address = second_host + ":" + std::to_string(port);
      DeformdProcess second({"--listen", address, "--workers", "1"});
      const std::optional<int> code = second.Wait(std::chrono::seconds(30));
      ASSERT_TRUE(code.has_value())
          << "a second server started on " << address << ": " << second.output();
      EXPECT_EQ(*code, 1) << address;
      EXPECT_THAT(second.output(), HasSubstr(std::to_string(port))) << address;
    }
    EXPECT_TRUE(first.running());
    first.Signal(SIGTERM);
    EXPECT_EQ(first.Wait(std::chrono::seconds(10)), std::optional<int>(0));
  }
}

// Server reflection over a generic stream: the responses to `requests` (serialized
// ServerReflectionRequest messages), or an empty vector on failure.
std::vector<std::string> AskReflection(const std::string& target,
                                       const std::vector<std::string>& requests) {
  auto channel = grpc::CreateChannel(target, grpc::InsecureChannelCredentials());
  grpc::GenericStub stub(channel);
  grpc::CompletionQueue queue;
  grpc::ClientContext context;
  context.set_deadline(std::chrono::system_clock::now() + std::chrono::seconds(20));
  auto call = stub.PrepareCall(
      &context, "/grpc.reflection.v1alpha.ServerReflection/ServerReflectionInfo", &queue);
  void* tag = nullptr;
  bool ok = false;
  auto step = [&] { return queue.Next(&tag, &ok) && ok; };
  call->StartCall(reinterpret_cast<void*>(1));
  std::vector<std::string> responses;
  if (!step()) return responses;
  for (const std::string& request : requests) {
    grpc::Slice slice(request);
    grpc::ByteBuffer buffer(&slice, 1);
    call->Write(buffer, reinterpret_cast<void*>(2));
    if (!step()) return responses;
    grpc::ByteBuffer reply;
    call->Read(&reply, reinterpret_cast<void*>(3));
    if (!step()) return responses;
    std::vector<grpc::Slice> slices;
    (void)reply.Dump(&slices);
    std::string bytes;
    for (const grpc::Slice& s : slices)
      bytes.append(reinterpret_cast<const char*>(s.begin()), s.size());
    responses.push_back(bytes);
  }
  call->WritesDone(reinterpret_cast<void*>(4));
  step();
  grpc::Status status;
  call->Finish(&status, reinterpret_cast<void*>(5));
  step();
  return responses;
}

// One length-delimited field of a message.
std::string Field(int number, const std::string& value) {
  std::string out(1, static_cast<char>((number << 3) | 2));
  std::size_t length = value.size();
  while (length >= 0x80) {
    out.push_back(static_cast<char>((length & 0x7f) | 0x80));
    length >>= 7;
  }
  out.push_back(static_cast<char>(length));
  return out + value;
}

// The length-delimited values of field `number` in `message`.
std::vector<std::string> Values(const std::string& message, int number) {
  google::protobuf::UnknownFieldSet fields;
  std::vector<std::string> values;
  if (!fields.ParseFromString(message)) return values;
  for (int i = 0; i < fields.field_count(); ++i) {
    const google::protobuf::UnknownField& field = fields.field(i);
    if (field.number() == number &&
        field.type() == google::protobuf::UnknownField::TYPE_LENGTH_DELIMITED) {
      values.push_back(field.length_delimited());
    }
  }
  return values;
}

// Reflection listed grpc.health.v1.Health but could not describe it: its descriptor was not
// linked into deformd (grpc/grpc#36665). The real executable, as buf curl would see it.
TEST(HostileDeployment, ReflectionDescribesTheHealthService) {
  DeformdProcess server({"--listen", "127.0.0.1:0", "--workers", "1"});
  const int port = server.WaitForListeningPort();
  ASSERT_GT(port, 0) << server.output();
  // ServerReflectionRequest: list_services = 7, file_containing_symbol = 4.
  const std::vector<std::string> responses = AskReflection(
      "127.0.0.1:" + std::to_string(port), {Field(7, "*"), Field(4, "grpc.health.v1.Health")});
  ASSERT_EQ(responses.size(), 2u);
  // ServerReflectionResponse.list_services_response = 6 { service = 1 { name = 1 } }.
  std::vector<std::string> names;
  for (const std::string& list : Values(responses[0], 6)) {
    for (const std::string& service : Values(list, 1)) {
      for (const std::string& name : Values(service, 1)) names.push_back(name);
    }
  }
  EXPECT_NE(std::find(names.begin(), names.end(), "grpc.health.v1.Health"), names.end());
  EXPECT_NE(std::find(names.begin(), names.end(), "deform.v1.DeformService"), names.end());
  // file_descriptor_response = 4 { file_descriptor_proto = 1 }; error_response = 7.
  EXPECT_TRUE(Values(responses[1], 7).empty()) << "reflection cannot describe the health service";
  bool described = false;
  for (const std::string& files : Values(responses[1], 4)) {
    for (const std::string& bytes : Values(files, 1)) {
      google::protobuf::FileDescriptorProto file;
      ASSERT_TRUE(file.ParseFromString(bytes));
      for (const auto& service : file.service()) {
        if (file.package() == "grpc.health.v1" && service.name() == "Health") described = true;
      }
    }
  }
  EXPECT_TRUE(described);
  server.Signal(SIGTERM);
  EXPECT_EQ(server.Wait(std::chrono::seconds(10)), std::optional<int>(0));
}

// Starts deformd (grace `grace_s`), opens an idle connection and, if asked, a frozen stream (a
// client that keeps sending poses and never reads its frames), sends SIGTERM and measures the
// time to exit. Expects exit code 0.
double SecondsToExitAfterSigterm(double grace_s, bool frozen_stream) {
  DeformdProcess server({"--listen", "127.0.0.1:0", "--workers", "2", "--shutdown-grace-s",
                         std::to_string(grace_s), "--preload-phantom", "2000"});
  const int port = server.WaitForListeningPort();
  EXPECT_GT(port, 0) << server.output();
  if (port == 0) return 1e9;
  const std::string target = "127.0.0.1:" + std::to_string(port);

  // The idle connection: connected, one call done, nothing since.
  client::DeformClient idle(target);
  EXPECT_TRUE(idle.WaitForReady(10'000));
  std::vector<v1::MeshSummary> meshes;
  EXPECT_TRUE(idle.ListMeshes(&meshes).ok());
  EXPECT_EQ(meshes.size(), 1u);
  if (meshes.size() != 1) return 1e9;

  auto stub =
      v1::DeformService::NewStub(grpc::CreateChannel(target, grpc::InsecureChannelCredentials()));
  grpc::ClientContext context;
  std::unique_ptr<grpc::ClientReaderWriter<v1::DeformRequest, v1::DeformResponse>> frozen;
  std::atomic<bool> stop{false};
  std::thread sender;
  if (frozen_stream) {
    frozen = stub->Deform(&context);
    v1::DeformRequest start;
    start.mutable_start()->set_mesh_id(meshes[0].mesh_id());
    EXPECT_TRUE(frozen->Write(start));
    sender = std::thread([&] {
      for (std::uint64_t k = 1; !stop; ++k) {
        v1::DeformRequest request;
        *request.mutable_pose() = KneePose(k, static_cast<double>(k % 90));
        if (!frozen->Write(request)) break;
        std::this_thread::sleep_for(std::chrono::milliseconds(2));
      }
    });
  }
  // Long enough for the unread frames (24 KB each) to fill the flow-control windows.
  std::this_thread::sleep_for(std::chrono::seconds(2));

  const Clock::time_point signalled = Clock::now();
  server.Signal(SIGTERM);
  const std::optional<int> code = server.Wait(std::chrono::seconds(30));
  const double elapsed = SecondsSince(signalled);
  stop = true;
  context.TryCancel();
  if (sender.joinable()) sender.join();
  EXPECT_TRUE(code.has_value()) << "deformd still runs 30 s after SIGTERM";
  EXPECT_EQ(code.value_or(-1), 0) << server.output();
  return elapsed;
}

// SIGTERM used to wait out the whole grace period for an idle connection. With an idle
// connection, and with a frozen stream besides, deformd exits 0 within the grace period.
TEST(HostileDeployment, SigtermExitsWithinTheGracePeriodWhateverTheClientsDo) {
  const double grace_s = 3;
  const double idle = SecondsToExitAfterSigterm(grace_s, /*frozen_stream=*/false);
  EXPECT_LT(idle, grace_s);
  const double frozen = SecondsToExitAfterSigterm(grace_s, /*frozen_stream=*/true);
  EXPECT_LT(frozen, grace_s);
  std::printf(
      "SIGTERM to exit 0 (grace %.0f s): %.2f s with an idle connection, %.2f s with an "
      "idle connection and a frozen stream\n",
      grace_s, idle, frozen);
}

}  // namespace
}  // namespace deform::test_support
