// The table of served gRPC methods (grpc_methods.h) against the proto: every DeformService method
// is listed with its streaming type, and a name is found only when served.
#include "service/metrics/grpc_methods.h"

#include <google/protobuf/descriptor.h>
#include <gtest/gtest.h>

#include <string>

#include "deform/v1/deform.pb.h"

namespace deform::service {
namespace {

GrpcType TypeOf(const google::protobuf::MethodDescriptor& method) {
  if (method.client_streaming()) {
    return method.server_streaming() ? GrpcType::kBidiStream : GrpcType::kClientStream;
  }
  return method.server_streaming() ? GrpcType::kServerStream : GrpcType::kUnary;
}

TEST(GrpcMethodsTest, EveryDeformServiceMethodIsListedWithItsType) {
  const google::protobuf::ServiceDescriptor* service =
      v1::DeformRequest::descriptor()->file()->FindServiceByName("DeformService");
  ASSERT_NE(service, nullptr);
  int listed = 0;
  for (const GrpcMethod& row : kServedGrpcMethods) listed += row.service == service->full_name();
  EXPECT_EQ(listed, service->method_count());
  for (int i = 0; i < service->method_count(); ++i) {
    const google::protobuf::MethodDescriptor& method = *service->method(i);
    const int index = ServedGrpcMethodIndex("/" + service->full_name() + "/" + method.name());
    ASSERT_GE(index, 0) << method.name() << " is not in kServedGrpcMethods";
    EXPECT_EQ(kServedGrpcMethods[index].type, TypeOf(method)) << method.name();
  }
}

TEST(GrpcMethodsTest, FindsOnlyServedNames) {
  EXPECT_GE(ServedGrpcMethodIndex("/grpc.health.v1.Health/Check"), 0);
  EXPECT_GE(ServedGrpcMethodIndex("/grpc.reflection.v1alpha.ServerReflection/ServerReflectionInfo"),
            0);
  EXPECT_EQ(ServedGrpcMethodIndex("/deform.v1.DeformService/NoSuchMethod"), -1);
  EXPECT_EQ(ServedGrpcMethodIndex("/no.Such/Deform"), -1);
  EXPECT_EQ(ServedGrpcMethodIndex("deform.v1.DeformService/Deform"), -1);
  EXPECT_EQ(ServedGrpcMethodIndex(""), -1);
  EXPECT_STREQ(GrpcTypeName(GrpcType::kBidiStream), "bidi_stream");
  EXPECT_STREQ(GrpcTypeName(GrpcType::kServerStream), "server_stream");
}

}  // namespace
}  // namespace deform::service
