// ToGrpcStatus: the code and the message pass one to one; a status naming its subject carries a
// google.rpc.Status (same code and message) with a BadRequest (INVALID_ARGUMENT) or a
// QuotaFailure (RESOURCE_EXHAUSTED) as error_details; every other status carries none.
#include "service/transport/status_mapping.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <string>

#include "google/rpc/error_details.pb.h"
#include "google/rpc/status.pb.h"
#include "service/base/request_limits.h"

namespace deform::service {
namespace {

using ::testing::HasSubstr;
using ::testing::StartsWith;

// The details of `status`, parsed; fails the test when there are none or they do not parse.
google::rpc::Status DetailsOf(const grpc::Status& status) {
  google::rpc::Status details;
  EXPECT_FALSE(status.error_details().empty());
  EXPECT_TRUE(details.ParseFromString(status.error_details()));
  return details;
}

TEST(StatusMappingTest, InvalidArgumentWithASubjectCarriesABadRequestNamingTheField) {
  const Status status = Status::InvalidArgument("upload.bone_surfaces[0].mesh is empty")
                            .WithSubject("upload.bone_surfaces[0].mesh");
  const grpc::Status mapped = ToGrpcStatus(status);
  EXPECT_EQ(mapped.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_EQ(mapped.error_message(), "upload.bone_surfaces[0].mesh is empty");

  const google::rpc::Status details = DetailsOf(mapped);
  EXPECT_EQ(details.code(), static_cast<int>(grpc::StatusCode::INVALID_ARGUMENT));
  EXPECT_EQ(details.message(), mapped.error_message());
  ASSERT_EQ(details.details_size(), 1);
  google::rpc::BadRequest bad_request;
  ASSERT_TRUE(details.details(0).UnpackTo(&bad_request));
  ASSERT_EQ(bad_request.field_violations_size(), 1);
  EXPECT_EQ(bad_request.field_violations(0).field(), "upload.bone_surfaces[0].mesh");
  EXPECT_EQ(bad_request.field_violations(0).description(), status.message());
}

TEST(StatusMappingTest, ResourceExhaustedNamingItsLimitCarriesAQuotaFailure) {
  const Status status = Status::ResourceExhausted("tenant mesh limit reached")
                            .WithLimit("tenant:ward-a", "--tenant-max-meshes");
  const grpc::Status mapped = ToGrpcStatus(status);
  EXPECT_EQ(mapped.error_code(), grpc::StatusCode::RESOURCE_EXHAUSTED);
  EXPECT_EQ(mapped.error_message(), "tenant mesh limit reached");

  const google::rpc::Status details = DetailsOf(mapped);
  EXPECT_EQ(details.code(), static_cast<int>(grpc::StatusCode::RESOURCE_EXHAUSTED));
  EXPECT_EQ(details.message(), mapped.error_message());
  ASSERT_EQ(details.details_size(), 1);
  EXPECT_FALSE(details.details(0).Is<google::rpc::BadRequest>());
  google::rpc::QuotaFailure quota_failure;
  ASSERT_TRUE(details.details(0).UnpackTo(&quota_failure));
  ASSERT_EQ(quota_failure.violations_size(), 1);
  EXPECT_EQ(quota_failure.violations(0).subject(), "tenant:ward-a");
  EXPECT_THAT(quota_failure.violations(0).description(), StartsWith("--tenant-max-meshes: "));
  EXPECT_THAT(quota_failure.violations(0).description(), HasSubstr("tenant mesh limit reached"));
}

TEST(StatusMappingTest, StatusesWithoutASubjectOrOfOtherCodesCarryNoDetails) {
  EXPECT_TRUE(ToGrpcStatus(Status::Ok()).ok());
  EXPECT_TRUE(ToGrpcStatus(Status::Ok()).error_details().empty());
  EXPECT_TRUE(ToGrpcStatus(Status::InvalidArgument("no subject")).error_details().empty());
  EXPECT_TRUE(ToGrpcStatus(Status::ResourceExhausted("no limit")).error_details().empty());
  // A subject on a code that has no standard detail here is not sent.
  const grpc::Status not_found = ToGrpcStatus(Status::NotFound("no mesh").WithSubject("mesh_id"));
  EXPECT_EQ(not_found.error_code(), grpc::StatusCode::NOT_FOUND);
  EXPECT_TRUE(not_found.error_details().empty());
  // A RESOURCE_EXHAUSTED subject without its option names no limit: no QuotaFailure.
  EXPECT_TRUE(
      ToGrpcStatus(Status::ResourceExhausted("x").WithSubject("server")).error_details().empty());
}

TEST(StatusMappingTest, TheDetailsRepeatTheMessageCutLikeTheStatus) {
  const std::string field(5000, 'f');
  const Status status = Status::InvalidArgument(std::string(5000, 'm')).WithSubject(field);
  const grpc::Status mapped = ToGrpcStatus(status);
  EXPECT_EQ(mapped.error_message().size(), kMaxStatusMessageBytes);
  const google::rpc::Status details = DetailsOf(mapped);
  EXPECT_EQ(details.message(), mapped.error_message());
  google::rpc::BadRequest bad_request;
  ASSERT_TRUE(details.details(0).UnpackTo(&bad_request));
  EXPECT_EQ(bad_request.field_violations(0).field().size(), kMaxStatusMessageBytes);
  EXPECT_EQ(bad_request.field_violations(0).description().size(), kMaxStatusMessageBytes);
}

TEST(StatusMappingTest, SubjectsSurviveContextAndNestInFields) {
  const Status inner = Status::InvalidArgument("weight 7 is out of range").WithSubject("weight");
  const Status outer = InField(inner.WithContext("region_weights[2]"), "region_weights[2]");
  EXPECT_EQ(outer.message(), "region_weights[2]: weight 7 is out of range");
  EXPECT_EQ(outer.subject(), "region_weights[2].weight");
  EXPECT_EQ(InField(Status::InvalidArgument("bad"), "options").subject(), "options");
  // Only INVALID_ARGUMENT's subject is a field path: a limit's scope is kept as it is.
  const Status limit = Status::ResourceExhausted("full").WithLimit("server", "--max-vertices");
  EXPECT_EQ(InField(limit, "chunk").subject(), "server");
  EXPECT_EQ(InField(limit, "chunk").limit(), "--max-vertices");
  EXPECT_TRUE(Status::Ok().WithSubject("name").subject().empty());
}

}  // namespace
}  // namespace deform::service
