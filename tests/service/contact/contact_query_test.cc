// The QueryContact stream end to end through the real client library against an in-process
// server: a sphere pressed into the phantom's rest skin, the same query against a Deform stream's
// latest frame, the tenancy rules (another tenant's mesh or stream is an unknown id), the stream
// limit, and bad queries ending only their own stream.
#include "contact_query.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "service/registry/mesh_id.h"
#include "tests/service/support/service_fixture.h"
#include "tests/service/support/temp_dir.h"
#include "tests/service/support/token_file.h"

namespace deform::test_support {
namespace {

using ::testing::HasSubstr;

constexpr int kVertices = 800;
// The 800-vertex phantom's thigh front is at y 6, z 0.66 (tool_stream_test.cc): this sphere is
// pressed about 0.1 into it.
constexpr double kPressedZ = 0.86;
constexpr double kRadius = 0.3;

v1::ToolState Sphere(double x, double y, double z, double radius) {
  v1::ToolState tool;
  tool.set_shape(v1::ToolState::SHAPE_SPHERE);
  tool.mutable_center()->set_x(x);
  tool.mutable_center()->set_y(y);
  tool.mutable_center()->set_z(z);
  tool.set_radius(radius);
  return tool;
}

v1::ContactQueryStart StartOn(const std::string& mesh_id, std::uint64_t stream_id = 0) {
  v1::ContactQueryStart start;
  start.set_mesh_id(mesh_id);
  start.set_deform_stream_id(stream_id);
  return start;
}

double Norm(const v1::Vector3& v) {
  return std::sqrt(v.x() * v.x() + v.y() * v.y() + v.z() * v.z());
}

class ContactQueryTest : public ServiceTest {};

TEST_F(ContactQueryTest, ASpherePressedIntoTheRestSkinReportsItsDepthAndForce) {
  StartServer();
  const std::string mesh_id = LoadPhantom(kVertices);
  std::unique_ptr<client::ContactQuery> query;
  v1::ContactQueryStart start = StartOn(mesh_id);
  start.set_stiffness(50);
  const grpc::Status opened = client_->OpenContactQuery(start, &query);
  ASSERT_TRUE(opened.ok()) << opened.error_message();
  const double diagonal = query->started().bounding_box_diagonal();
  EXPECT_NEAR(diagonal, 8.97, 0.01);
  EXPECT_EQ(query->started().stiffness(), 50);

  v1::ContactResult pressed;
  ASSERT_TRUE(query->Query(Sphere(0, 6, kPressedZ, kRadius), &pressed).ok());
  EXPECT_EQ(pressed.sequence(), 1u);
  EXPECT_EQ(pressed.frame_number(), 0u);  // the rest pose
  EXPECT_GT(pressed.depth(), 0.05);
  EXPECT_LT(pressed.depth(), 0.15);
  EXPECT_NEAR(pressed.depth(), kRadius - pressed.signed_distance(), 1e-12);
  EXPECT_NEAR(Norm(pressed.normal()), 1, 1e-9);
  EXPECT_GT(pressed.normal().z(), 0.7);  // the thigh's front faces +z
  EXPECT_GT(pressed.material_weight(), 0);
  const double magnitude = 50 * pressed.material_weight() * pressed.depth() / diagonal;
  EXPECT_NEAR(Norm(pressed.force()), magnitude, 1e-9 * magnitude);
  EXPECT_NEAR(pressed.force().z(), magnitude * pressed.normal().z(), 1e-9 * magnitude);

  v1::ContactResult apart;
  ASSERT_TRUE(query->Query(Sphere(0, 6, kPressedZ + 1, kRadius), &apart).ok());
  EXPECT_EQ(apart.sequence(), 2u);
  EXPECT_EQ(apart.depth(), 0);
  EXPECT_EQ(Norm(apart.force()), 0);
  EXPECT_NEAR(apart.signed_distance(), pressed.signed_distance() + 1, 0.05);
  EXPECT_TRUE(query->Close().ok());
  ExpectBackgroundStreamAlive();
}

TEST_F(ContactQueryTest, QueriesFollowTheNamedDeformStreamsLatestFrame) {
  StartServer();
  const std::string mesh_id = LoadPhantom(kVertices);
  v1::GetMeshInfoResponse info;
  ASSERT_TRUE(client_->GetMeshInfo(mesh_id, true, &info).ok());
  StreamRecorder recorder(/*keep_positions=*/true);
  auto stream = OpenStream(mesh_id, recorder.Callbacks());
  ASSERT_TRUE(stream->SendPose(KneePose(7, 80)));
  ASSERT_TRUE(recorder.WaitForFrameWithSequence(7));
  const v1::DeformFrame frame = recorder.last_frame();
  ASSERT_NE(frame.stream_id(), 0u);

  // The vertex the bend moved the most: at rest it is far from the bent skin's surface.
  const std::vector<float> bent = client::DecodePositions(frame.positions());
  const std::vector<float> rest = client::DecodePositions(info.rest_positions());
  ASSERT_EQ(bent.size(), rest.size());
  int moved = 0;
  double farthest = 0;
  for (std::size_t v = 0; v < bent.size() / 3; ++v) {
    const double dx = bent[3 * v] - rest[3 * v], dy = bent[3 * v + 1] - rest[3 * v + 1],
                 dz = bent[3 * v + 2] - rest[3 * v + 2];
    const double distance = std::sqrt(dx * dx + dy * dy + dz * dz);
    if (distance > farthest) {
      farthest = distance;
      moved = static_cast<int>(v);
    }
  }
  ASSERT_GT(farthest, 0.5);
  const v1::ToolState at_bent =
      Sphere(bent[3 * moved], bent[3 * moved + 1], bent[3 * moved + 2], 0.05);

  std::unique_ptr<client::ContactQuery> on_stream;
  ASSERT_TRUE(client_->OpenContactQuery(StartOn(mesh_id, frame.stream_id()), &on_stream).ok());
  v1::ContactResult result;
  ASSERT_TRUE(on_stream->Query(at_bent, &result).ok());
  EXPECT_EQ(result.frame_number(), 1u);
  EXPECT_EQ(result.frame_sequence(), 7u);
  // The sphere sits on a vertex of the frame (float32 on the wire).
  EXPECT_LT(std::abs(result.signed_distance()), 1e-5);
  EXPECT_NEAR(result.depth(), 0.05, 1e-5);

  std::unique_ptr<client::ContactQuery> at_rest;
  ASSERT_TRUE(client_->OpenContactQuery(StartOn(mesh_id), &at_rest).ok());
  v1::ContactResult rest_result;
  ASSERT_TRUE(at_rest->Query(at_bent, &rest_result).ok());
  EXPECT_GT(std::abs(rest_result.signed_distance()), 0.1);

  // A newer frame: the next query refits to it.
  ASSERT_TRUE(stream->SendPose(KneePose(8, 0)));
  ASSERT_TRUE(recorder.WaitForFrameWithSequence(8));
  ASSERT_TRUE(on_stream->Query(at_bent, &result).ok());
  EXPECT_EQ(result.frame_number(), 2u);
  EXPECT_EQ(result.frame_sequence(), 8u);
  EXPECT_NEAR(result.signed_distance(), rest_result.signed_distance(), 1e-4);
  EXPECT_TRUE(on_stream->Close().ok());
  EXPECT_TRUE(at_rest->Close().ok());
  stream->Close();
  EXPECT_TRUE(stream->Wait().ok());
}

TEST_F(ContactQueryTest, BadStartsAndQueriesEndOnlyTheirOwnStream) {
  StartServer();
  const std::string mesh_id = LoadPhantom(kVertices);
  std::unique_ptr<client::ContactQuery> query;
  const grpc::Status unknown = client_->OpenContactQuery(StartOn(service::NewMeshId()), &query);
  EXPECT_EQ(unknown.error_code(), grpc::StatusCode::NOT_FOUND);
  EXPECT_EQ(query, nullptr);
  const grpc::Status no_stream = client_->OpenContactQuery(StartOn(mesh_id, 987654), &query);
  EXPECT_EQ(no_stream.error_code(), grpc::StatusCode::NOT_FOUND);
  EXPECT_THAT(no_stream.error_message(), HasSubstr("no open Deform stream 987654"));
  v1::ContactQueryStart soft = StartOn(mesh_id);
  soft.set_stiffness(-1);
  EXPECT_EQ(client_->OpenContactQuery(soft, &query).error_code(),
            grpc::StatusCode::INVALID_ARGUMENT);

  ASSERT_TRUE(client_->OpenContactQuery(StartOn(mesh_id), &query).ok());
  v1::ContactResult result;
  const grpc::Status bad = query->Query(Sphere(0, 6, kPressedZ, -1), &result);
  EXPECT_EQ(bad.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_THAT(bad.error_message(), HasSubstr("query 1"));
  EXPECT_EQ(query->Query(Sphere(0, 6, kPressedZ, kRadius), &result).error_code(),
            grpc::StatusCode::INVALID_ARGUMENT);  // the stream has ended
  v1::ToolState no_shape = Sphere(0, 6, kPressedZ, kRadius);
  no_shape.set_shape(v1::ToolState::SHAPE_UNSPECIFIED);
  ASSERT_TRUE(client_->OpenContactQuery(StartOn(mesh_id), &query).ok());
  EXPECT_EQ(query->Query(no_shape, &result).error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  ExpectBackgroundStreamAlive();
}

std::string Tokens() {
  return TokenLine("token-of-ward-a", "ward-a", "tenant") +
         TokenLine("token-of-ward-b", "ward-b", "tenant");
}

TEST(ContactQueryTenancyTest, AnotherTenantsMeshOrStreamIsAnUnknownId) {
  TempDir dir;
  service::ServerOptions options = TestServerOptions();
  options.limits.tenant_max_streams = 2;
  TestServer server(options, dir.Write("tokens", Tokens()));
  auto ward_a = server.NewClient(WithToken("token-of-ward-a"));
  auto ward_b = server.NewClient(WithToken("token-of-ward-b"));
  ASSERT_TRUE(ward_a->WaitForReady(60'000));
  v1::MeshSummary a_summary, b_summary;
  ASSERT_TRUE(ward_a->LoadPhantom(kVertices, {}, &a_summary).ok());
  ASSERT_TRUE(ward_b->LoadPhantom(kVertices, {}, &b_summary).ok());
  StreamRecorder recorder;
  auto a_stream = ward_a->OpenStream(a_summary.mesh_id(), recorder.Callbacks());
  ASSERT_TRUE(a_stream->SendPose(KneePose(1, 30)));
  ASSERT_TRUE(recorder.WaitForFrames(1));
  const std::uint64_t a_stream_id = recorder.last_frame().stream_id();
  ASSERT_NE(a_stream_id, 0u);

  std::unique_ptr<client::ContactQuery> query;
  // Ward A's mesh, asked for by ward B: what an id that does not exist gets.
  const std::string unknown_id = service::NewMeshId();
  const grpc::Status unknown = ward_b->OpenContactQuery(StartOn(unknown_id), &query);
  const grpc::Status other = ward_b->OpenContactQuery(StartOn(a_summary.mesh_id()), &query);
  EXPECT_EQ(other.error_code(), grpc::StatusCode::NOT_FOUND);
  std::string expected = unknown.error_message();
  expected.replace(expected.find(unknown_id), unknown_id.size(), a_summary.mesh_id());
  EXPECT_EQ(other.error_message(), expected);
  // Ward A's stream named from ward B's own mesh: as a stream id that does not exist.
  const std::uint64_t no_such_stream = a_stream_id + 1000;
  const grpc::Status no_stream =
      ward_b->OpenContactQuery(StartOn(b_summary.mesh_id(), no_such_stream), &query);
  const grpc::Status other_stream =
      ward_b->OpenContactQuery(StartOn(b_summary.mesh_id(), a_stream_id), &query);
  EXPECT_EQ(other_stream.error_code(), grpc::StatusCode::NOT_FOUND);
  expected = no_stream.error_message();
  expected.replace(expected.find(std::to_string(no_such_stream)),
                   std::to_string(no_such_stream).size(), std::to_string(a_stream_id));
  EXPECT_EQ(other_stream.error_message(), expected);

  // Ward A's own query counts against its two streams: the Deform stream and this one.
  std::unique_ptr<client::ContactQuery> own;
  ASSERT_TRUE(ward_a->OpenContactQuery(StartOn(a_summary.mesh_id(), a_stream_id), &own).ok());
  v1::ContactResult result;
  ASSERT_TRUE(own->Query(Sphere(0, 6, kPressedZ, kRadius), &result).ok());
  EXPECT_EQ(result.frame_sequence(), 1u);
  const grpc::Status third = ward_a->OpenContactQuery(StartOn(a_summary.mesh_id()), &query);
  EXPECT_EQ(third.error_code(), grpc::StatusCode::RESOURCE_EXHAUSTED);
  EXPECT_THAT(third.error_message(), HasSubstr("--tenant-max-streams"));
  EXPECT_TRUE(own->Close().ok());
  a_stream->Close();
  EXPECT_TRUE(a_stream->Wait().ok());
}

}  // namespace
}  // namespace deform::test_support
