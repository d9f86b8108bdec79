#include "contact_query.h"

#include <utility>

namespace deform::client {

ContactQuery::ContactQuery(
    std::unique_ptr<grpc::ClientContext> context,
    std::unique_ptr<
        grpc::ClientReaderWriter<deform::v1::QueryContactRequest, deform::v1::QueryContactResponse>>
        stream)
    : context_(std::move(context)), stream_(std::move(stream)) {}

ContactQuery::~ContactQuery() {
  if (!finished_) {
    context_->TryCancel();
    (void)stream_->Finish();
  }
}

grpc::Status ContactQuery::Open(deform::v1::DeformService::Stub* stub,
                                std::unique_ptr<grpc::ClientContext> context,
                                const deform::v1::ContactQueryStart& start,
                                std::unique_ptr<ContactQuery>* query) {
  query->reset();
  auto stream = stub->QueryContact(context.get());
  std::unique_ptr<ContactQuery> opened(new ContactQuery(std::move(context), std::move(stream)));
  *opened->request_.mutable_start() = start;
  if (!opened->stream_->Write(opened->request_) || !opened->stream_->Read(&opened->response_)) {
    return opened->FinishAfterFailure();
  }
  if (!opened->response_.has_started()) {
    opened->context_->TryCancel();
    opened->FinishAfterFailure();
    return grpc::Status(grpc::StatusCode::INTERNAL,
                        "QueryContact: the server's first answer "
                        "is not `started`");
  }
  opened->started_ = opened->response_.started();
  *query = std::move(opened);
  return grpc::Status::OK;
}

grpc::Status ContactQuery::Query(const deform::v1::ToolState& tool,
                                 deform::v1::ContactResult* result) {
  if (finished_) return final_status_;
  deform::v1::ContactQuery* query = request_.mutable_query();
  query->set_sequence(++sequence_);
  *query->mutable_tool() = tool;
  if (!stream_->Write(request_) || !stream_->Read(&response_)) return FinishAfterFailure();
  if (!response_.has_result() || response_.result().sequence() != sequence_) {
    context_->TryCancel();
    FinishAfterFailure();
    final_status_ = grpc::Status(
        grpc::StatusCode::INTERNAL,
        "QueryContact: an answer that is not the result of query " + std::to_string(sequence_));
    return final_status_;
  }
  result->Swap(response_.mutable_result());
  return grpc::Status::OK;
}

grpc::Status ContactQuery::Close() {
  if (finished_) return final_status_;
  stream_->WritesDone();
  // Nothing more is due: a result here would be one no query asked for.
  while (stream_->Read(&response_)) {
  }
  finished_ = true;
  final_status_ = stream_->Finish();
  return final_status_;
}

grpc::Status ContactQuery::FinishAfterFailure() {
  if (!finished_) {
    finished_ = true;
    final_status_ = stream_->Finish();
    if (final_status_.ok()) {
      final_status_ = grpc::Status(grpc::StatusCode::UNAVAILABLE, "QueryContact: stream ended");
    }
  }
  return final_status_;
}

}  // namespace deform::client
