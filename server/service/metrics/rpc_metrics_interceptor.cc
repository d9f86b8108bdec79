#include "service/metrics/rpc_metrics_interceptor.h"

#include <chrono>
#include <string>

#include "service/metrics/grpc_methods.h"

namespace deform::service {
namespace {

using Clock = std::chrono::steady_clock;

class RpcMetricsInterceptor : public grpc::experimental::Interceptor {
 public:
  RpcMetricsInterceptor(const char* method, ServiceMetrics* metrics)
      : method_(method != nullptr ? method : ""),
        grpc_method_(ServedGrpcMethodIndex(method_)),
        metrics_(metrics),
        start_(Clock::now()) {
    metrics_->GrpcStarted(grpc_method_);
  }

  void Intercept(grpc::experimental::InterceptorBatchMethods* methods) override {
    using grpc::experimental::InterceptionHookPoints;
    // A read that got no message (the client's end of stream, a cancel) has a null message.
    if (methods->QueryInterceptionHookPoint(InterceptionHookPoints::POST_RECV_MESSAGE) &&
        methods->GetRecvMessage() != nullptr) {
      metrics_->GrpcMessageReceived(grpc_method_);
    }
    if (methods->QueryInterceptionHookPoint(InterceptionHookPoints::PRE_SEND_MESSAGE)) {
      metrics_->GrpcMessageSent(grpc_method_);
    }
    if (methods->QueryInterceptionHookPoint(InterceptionHookPoints::PRE_SEND_STATUS)) {
      const int code = static_cast<int>(methods->GetSendStatus().error_code());
      metrics_->RpcFinished(method_, code);
      metrics_->GrpcHandled(grpc_method_, code,
                            std::chrono::duration<double>(Clock::now() - start_).count());
    }
    methods->Proceed();
  }

 private:
  std::string_view method_;  // gRPC's string, alive for the call
  int grpc_method_;          // -1: not a served method, not in grpc_server_*
  ServiceMetrics* metrics_;
  Clock::time_point start_;
};

}  // namespace

grpc::experimental::Interceptor* RpcMetricsInterceptorFactory::CreateServerInterceptor(
    grpc::experimental::ServerRpcInfo* info) {
  return new RpcMetricsInterceptor(info->method(), metrics_);
}

}  // namespace deform::service
