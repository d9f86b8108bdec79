// Machine-readable error details on real calls, read as a client of any language would: the
// status's error_details parsed as a google.rpc.Status, its details unpacked. An INVALID_ARGUMENT
// LoadMesh carries a BadRequest naming the request field; a refused load carries a QuotaFailure
// naming the limit's scope and option; a status the server cannot attribute carries none.
#include <gmock/gmock.h>
#include <grpcpp/grpcpp.h>
#include <gtest/gtest.h>

#include <string>

#include "deform_client.h"
#include "google/rpc/error_details.pb.h"
#include "google/rpc/status.pb.h"
#include "tests/service/support/service_fixture.h"
#include "tests/service/support/stream_recorder.h"

namespace deform::test_support {
namespace {

using ::testing::HasSubstr;
using ::testing::StartsWith;

// The google.rpc.Status a call ended with; fails the test when it carries none, when it does
// not parse, or when its code and message differ from the status's own.
google::rpc::Status RpcStatusOf(const grpc::Status& status) {
  google::rpc::Status details;
  EXPECT_FALSE(status.error_details().empty()) << "no error details: " << status.error_message();
  EXPECT_TRUE(details.ParseFromString(status.error_details()));
  EXPECT_EQ(details.code(), static_cast<int>(status.error_code()));
  EXPECT_EQ(details.message(), status.error_message());
  return details;
}

// The one field violation of a call's BadRequest.
google::rpc::BadRequest::FieldViolation FieldViolationOf(const grpc::Status& status) {
  const google::rpc::Status details = RpcStatusOf(status);
  google::rpc::BadRequest bad_request;
  EXPECT_EQ(details.details_size(), 1);
  if (details.details_size() > 0) {
    EXPECT_TRUE(details.details(0).UnpackTo(&bad_request));
  }
  EXPECT_EQ(bad_request.field_violations_size(), 1);
  return bad_request.field_violations_size() > 0 ? bad_request.field_violations(0)
                                                 : google::rpc::BadRequest::FieldViolation();
}

// The one violation of a call's QuotaFailure.
google::rpc::QuotaFailure::Violation QuotaViolationOf(const grpc::Status& status) {
  const google::rpc::Status details = RpcStatusOf(status);
  google::rpc::QuotaFailure quota_failure;
  EXPECT_EQ(details.details_size(), 1);
  if (details.details_size() > 0) {
    EXPECT_TRUE(details.details(0).UnpackTo(&quota_failure));
  }
  EXPECT_EQ(quota_failure.violations_size(), 1);
  return quota_failure.violations_size() > 0 ? quota_failure.violations(0)
                                             : google::rpc::QuotaFailure::Violation();
}

class ErrorDetailsTest : public ServiceTest {};

TEST_F(ErrorDetailsTest, InvalidLoadMeshHeadersNameTheFieldInABadRequest) {
  StartServer();
  v1::MeshSummary summary;
  const grpc::Status long_name = client_->LoadPhantom(300, {}, &summary, {}, std::string(300, 'n'));
  ASSERT_EQ(long_name.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  google::rpc::BadRequest::FieldViolation violation = FieldViolationOf(long_name);
  EXPECT_EQ(violation.field(), "name");
  EXPECT_THAT(violation.description(), HasSubstr("name is 300 bytes long"));

  // A bone surface without its mesh, beside a valid OBJ upload.
  v1::LoadMeshHeader header;
  v1::UploadSource* upload = header.mutable_upload();
  upload->set_format(v1::MESH_FORMAT_OBJ);
  upload->set_skeleton("j0 0 0 0\nj1 0 1 0\n#\n1 2\n");
  upload->set_skeleton_format(v1::SKELETON_FORMAT_TGF);
  v1::BoneSurfaceUpload* bone = upload->add_bone_surfaces();
  bone->set_bone("0");
  bone->set_format(v1::MESH_FORMAT_OBJ);
  const std::string obj = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
  const grpc::Status no_bone_mesh = client_->LoadMesh(header, obj, &summary);
  ASSERT_EQ(no_bone_mesh.error_code(), grpc::StatusCode::INVALID_ARGUMENT)
      << no_bone_mesh.error_message();
  EXPECT_EQ(FieldViolationOf(no_bone_mesh).field(), "upload.bone_surfaces[0].mesh");

  // A method option out of range, through the proto-to-core conversion of the options.
  v1::MethodOptions options;
  options.set_region_radius_factor(-1);
  const grpc::Status bad_option = client_->LoadPhantom(300, options, &summary);
  ASSERT_EQ(bad_option.error_code(), grpc::StatusCode::INVALID_ARGUMENT)
      << bad_option.error_message();
  EXPECT_EQ(FieldViolationOf(bad_option).field(), "options.region_radius_factor");
  ExpectBackgroundStreamAlive();
}

TEST_F(ErrorDetailsTest, TheMeshLimitIsNamedInAQuotaFailure) {
  service::ServerOptions server_options = TestServerOptions();
  server_options.limits.max_meshes = 1;  // the background phantom takes it
  StartServer(server_options);
  v1::MeshSummary summary;
  const grpc::Status refused = client_->LoadPhantom(300, {}, &summary);
  ASSERT_EQ(refused.error_code(), grpc::StatusCode::RESOURCE_EXHAUSTED) << refused.error_message();
  const google::rpc::QuotaFailure::Violation violation = QuotaViolationOf(refused);
  EXPECT_EQ(violation.subject(), "server");
  EXPECT_THAT(violation.description(), StartsWith("--max-meshes: "));
  EXPECT_THAT(violation.description(), HasSubstr("mesh limit reached"));
  ExpectBackgroundStreamAlive();
}

TEST_F(ErrorDetailsTest, TheUploadSizeLimitIsNamedInAQuotaFailure) {
  service::ServerOptions server_options = TestServerOptions();
  server_options.limits.max_upload_bytes = 1000;
  StartServer(server_options);
  v1::LoadMeshHeader header;
  v1::UploadSource* upload = header.mutable_upload();
  upload->set_format(v1::MESH_FORMAT_OBJ);
  upload->set_skeleton("j0 0 0 0\nj1 0 1 0\n#\n1 2\n");
  upload->set_skeleton_format(v1::SKELETON_FORMAT_TGF);
  v1::MeshSummary summary;
  const grpc::Status refused = client_->LoadMesh(header, std::string(2000, ' '), &summary);
  ASSERT_EQ(refused.error_code(), grpc::StatusCode::RESOURCE_EXHAUSTED) << refused.error_message();
  const google::rpc::QuotaFailure::Violation violation = QuotaViolationOf(refused);
  EXPECT_EQ(violation.subject(), "server");
  EXPECT_THAT(violation.description(), StartsWith("--max-upload-mb: "));
}

// The statuses that end a Deform stream at its start carry details as well.
TEST_F(ErrorDetailsTest, ADeformStreamRefusedAtItsStartNamesTheFieldOrTheLimit) {
  service::ServerOptions server_options = TestServerOptions();
  server_options.limits.max_streams = 1;  // the background stream takes it
  StartServer(server_options);
  StreamRecorder long_id;
  auto stream = client_->OpenStream(std::string(200, 'i'), long_id.Callbacks());
  const grpc::Status refused_id = stream->Wait();
  ASSERT_EQ(refused_id.error_code(), grpc::StatusCode::INVALID_ARGUMENT)
      << refused_id.error_message();
  EXPECT_EQ(FieldViolationOf(refused_id).field(), "start.mesh_id");

  StreamRecorder second;
  stream = client_->OpenStream(background_mesh_id_, second.Callbacks());
  const grpc::Status refused = stream->Wait();
  ASSERT_EQ(refused.error_code(), grpc::StatusCode::RESOURCE_EXHAUSTED) << refused.error_message();
  const google::rpc::QuotaFailure::Violation violation = QuotaViolationOf(refused);
  EXPECT_EQ(violation.subject(), "server");
  EXPECT_THAT(violation.description(), StartsWith("--max-streams: "));
  ExpectBackgroundStreamAlive();
}

TEST_F(ErrorDetailsTest, StatusesWithoutASubjectCarryNoDetails) {
  StartServer();
  v1::GetMeshInfoResponse info;
  const grpc::Status unknown = client_->GetMeshInfo("no-such-mesh", false, &info);
  ASSERT_EQ(unknown.error_code(), grpc::StatusCode::NOT_FOUND) << unknown.error_message();
  EXPECT_TRUE(unknown.error_details().empty());
}

}  // namespace
}  // namespace deform::test_support
