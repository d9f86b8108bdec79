// The clients' status-code names come from the core's one table (core/base/status.h), read by
// gRPC's code numbers: every number must give the name Abseil, which gRPC builds on, gives it.
#include "status_names.h"

#include <absl/status/status.h>
#include <grpcpp/support/status.h>
#include <gtest/gtest.h>

#include "core/base/status.h"

namespace deform {
namespace {

TEST(StatusNames, EveryGrpcCodeHasItsCanonicalName) {
  for (int number = 0; number < kCanonicalStatusCodes; ++number) {
    EXPECT_EQ(client::StatusCodeName(static_cast<grpc::StatusCode>(number)),
              absl::StatusCodeToString(static_cast<absl::StatusCode>(number)))
        << "code " << number;
  }
}

TEST(StatusNames, NumbersOutsideTheCanonicalCodesHaveNone) {
  EXPECT_EQ(CanonicalStatusCodeName(-1), nullptr);
  EXPECT_EQ(CanonicalStatusCodeName(kCanonicalStatusCodes), nullptr);
  EXPECT_STREQ(client::StatusCodeName(static_cast<grpc::StatusCode>(kCanonicalStatusCodes)),
               "UNKNOWN_CODE");
}

TEST(StatusNames, TheCoresCodesAreNamedByTheirGrpcNumbers) {
  const StatusCode codes[] = {StatusCode::kOk,
                              StatusCode::kInvalidArgument,
                              StatusCode::kNotFound,
                              StatusCode::kResourceExhausted,
                              StatusCode::kFailedPrecondition,
                              StatusCode::kOutOfRange,
                              StatusCode::kInternal,
                              StatusCode::kUnauthenticated};
  for (const StatusCode code : codes) {
    EXPECT_STREQ(StatusCodeName(code),
                 client::StatusCodeName(static_cast<grpc::StatusCode>(static_cast<int>(code))));
  }
  EXPECT_EQ(Status::NotFound("no mesh 'arm'").ToString(), "NOT_FOUND: no mesh 'arm'");
}

TEST(StatusNames, StatusTextJoinsTheNameAndTheMessage) {
  EXPECT_EQ(client::StatusText(grpc::Status(grpc::StatusCode::UNAVAILABLE, "no server")),
            "UNAVAILABLE: no server");
  EXPECT_EQ(client::StatusText(grpc::Status(grpc::StatusCode::CANCELLED, "")), "CANCELLED");
  EXPECT_EQ(client::StatusText(grpc::Status(grpc::StatusCode::CANCELLED, "CANCELLED")),
            "CANCELLED");
}

}  // namespace
}  // namespace deform
