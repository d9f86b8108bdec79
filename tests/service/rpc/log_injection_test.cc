// No client string reaches the log with a raw control byte (base/log_text.h): control bytes
// (\n, \r, ESC, BEL) are fed through every request field that can reach a log line, over gRPC and
// the HTTP port, and the captured log (the default logger and the audit logger, as deformd writes
// them) holds none of them raw, and no line the client forged.
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <spdlog/sinks/ostream_sink.h>
#include <spdlog/spdlog.h>

#include <chrono>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "deform/v1/deform.pb.h"
#include "tests/service/support/log_capture.h"
#include "tests/service/support/raw_http.h"
#include "tests/service/support/stream_recorder.h"
#include "tests/service/support/test_server.h"

namespace deform::test_support {
namespace {

using ::testing::HasSubstr;

// Each field's value: a forged audit line, a carriage return, an ANSI colour and a bell.
const std::string kHostile = "x\n[info] [audit] tenant=other forged\r\x1b[31mred\x07y";

TEST(LogInjectionTest, ControlBytesInEveryLoggedFieldReachNoLogLineRaw) {
  web::WebOptions web_options;
  TestServer server(TestServerOptions(), "", true, web_options);
  auto client = server.NewClient();
  ASSERT_TRUE(client->WaitForReady(60'000));
  // The audit logger exists once something was audited.
  std::vector<v1::MeshSummary> meshes;
  ASSERT_TRUE(client->ListMeshes(&meshes).ok());
  LogCapture capture;

  // A load's name, and a mesh to stream on.
  v1::MeshSummary summary;
  ASSERT_TRUE(client->LoadPhantom(200, {}, &summary, {}, kHostile).ok());
  // Upload fields that end in an error message: options' joint names, bone surface name and bone,
  // the mesh and skeleton bytes themselves.
  v1::MethodOptions options;
  options.add_region_radii()->set_joint(kHostile);
  EXPECT_FALSE(client->LoadPhantom(200, options, &summary, {}, "radius").ok());
  v1::LoadMeshHeader header;
  header.set_name(kHostile);
  v1::UploadSource* upload = header.mutable_upload();
  upload->set_format(v1::MESH_FORMAT_OBJ);
  upload->set_skeleton_format(v1::SKELETON_FORMAT_TGF);
  upload->set_skeleton("1 0 0 0\n2 0 1 0\n1 2\n" + kHostile);
  v1::BoneSurfaceUpload* bone = upload->add_bone_surfaces();
  bone->set_name(kHostile);
  bone->set_bone(kHostile);
  bone->set_blend_bone(kHostile);
  bone->set_format(v1::MESH_FORMAT_OBJ);
  bone->set_mesh(kHostile);
  EXPECT_FALSE(client->LoadMesh(header, "v 0 0 0\n" + kHostile + "\nf 1 2 3\n", &summary).ok());
  // Mesh ids: the unary calls and DeformStart.
  v1::GetMeshInfoResponse info;
  EXPECT_EQ(client->GetMeshInfo(kHostile, false, &info).error_code(), grpc::StatusCode::NOT_FOUND);
  EXPECT_EQ(client->UnloadMesh(kHostile).error_code(), grpc::StatusCode::NOT_FOUND);
  {
    StreamRecorder recorder;
    auto stream = client->OpenStream(kHostile, recorder.Callbacks());
    EXPECT_EQ(stream->Wait().error_code(), grpc::StatusCode::NOT_FOUND);
  }
  // The server writes the stream's closing line once the call is done, after the client has its
  // status.
  EXPECT_TRUE(capture.WaitFor("closed (no mesh with id", std::chrono::seconds(30)));
  // A stream's poses and stiffness updates.
  ASSERT_TRUE(client->ListMeshes(&meshes).ok());
  ASSERT_EQ(meshes.size(), 1u);
  {
    StreamRecorder recorder;
    auto stream = client->OpenStream(meshes[0].mesh_id(), recorder.Callbacks());
    v1::PoseUpdate pose;
    pose.set_sequence(1);
    v1::JointAngle* angle = pose.add_angles();
    angle->set_joint(kHostile);
    angle->set_axis(kHostile);
    angle->set_degrees(10);
    pose.add_rotations()->set_joint(kHostile);
    EXPECT_TRUE(stream->SendPose(pose));
    EXPECT_TRUE(recorder.WaitForNotice(v1::Notice::KIND_POSE_REJECTED));
    v1::StiffnessUpdate stiffness;
    v1::RegionWeight* weight = stiffness.add_region_weights();
    weight->set_joint(kHostile);
    weight->set_weight(2);
    EXPECT_TRUE(stream->SendStiffness(stiffness));
    EXPECT_TRUE(recorder.WaitForNotice(v1::Notice::KIND_STIFFNESS_REJECTED));
    stream->Close();
    stream->Wait();
  }
  // The HTTP port's headers (a header cannot carry control bytes, but bytes from 0x80 it can).
  const std::string bytes = "\xff\x9b";
  RawHttpExchange(server.web_port(), "GET / HTTP/1.1\r\nHost: evil" + bytes +
                                         "\r\nOrigin: http://o" + bytes +
                                         "\r\nConnection: close\r\n\r\n");
  const std::string text = capture.Stop();

  // The fields did reach the log (escaped), the three lines of the issue among them.
  EXPECT_THAT(text, HasSubstr("name='x\\n[info] [audit] tenant=other forged\\r\\x1b[31mred\\x07y"));
  EXPECT_THAT(text, HasSubstr("region_weights: no joint named 'x\\n[info]"));
  EXPECT_THAT(text, HasSubstr("ending: no mesh with id 'x\\n[info]"));
  EXPECT_THAT(text, HasSubstr("closed (no mesh with id 'x\\n[info]"));
  EXPECT_THAT(text, HasSubstr("Host 'evil\\xff\\x9b'"));
  // No raw control byte: every line is "<...>\n", with nothing but printable ASCII inside.
  std::size_t line_start = 0;
  int lines = 0;
  for (std::size_t i = 0; i < text.size(); ++i) {
    const auto c = static_cast<unsigned char>(text[i]);
    if (c == '\n') {
      EXPECT_EQ(text[line_start], '<') << text.substr(line_start, i - line_start);
      EXPECT_EQ(text[i - 1], '>') << text.substr(line_start, i - line_start);
      line_start = i + 1;
      ++lines;
      continue;
    }
    ASSERT_TRUE(c >= 0x20 && c < 0x7f) << "raw byte " << static_cast<int>(c)
                                       << " in: " << text.substr(line_start, i - line_start + 1);
  }
  EXPECT_GT(lines, 10);
  EXPECT_EQ(text.find("\n<[info] [audit] tenant=other"), std::string::npos);
}

}  // namespace
}  // namespace deform::test_support
