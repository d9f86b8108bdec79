// A gRPC server interceptor that counts every RPC: deformd_rpcs_total by method and status code
// (ServiceMetrics::RpcFinished), whatever path finished it (the service's reactors, a call
// refused before a reactor existed, or gRPC itself: a deadline, a cancelled or unknown call), and
// the standard grpc_server_* metrics for the methods of grpc_methods.h: the call's start (when
// gRPC creates the interceptor), each message received and sent, and its status with the time
// since its start.
#pragma once

#include <grpcpp/support/server_interceptor.h>

#include "service/metrics/service_metrics.h"

namespace deform::service {

// Creates one counting interceptor per RPC. `metrics` must outlive the server.
class RpcMetricsInterceptorFactory : public grpc::experimental::ServerInterceptorFactoryInterface {
 public:
  explicit RpcMetricsInterceptorFactory(ServiceMetrics* metrics) : metrics_(metrics) {}
  grpc::experimental::Interceptor* CreateServerInterceptor(
      grpc::experimental::ServerRpcInfo* info) override;

 private:
  ServiceMetrics* metrics_;
};

}  // namespace deform::service
