// A QueryContact stream (docs/instruments.md): a tool's contact with the skin, one blocking
// round trip a query, for a haptic loop. Open it with DeformClient::OpenContactQuery.
//
// Thread safety: one thread at a time per ContactQuery (a haptic loop owns it).
#pragma once

#include <grpcpp/grpcpp.h>

#include <cstdint>
#include <memory>

#include "deform/v1/deform.grpc.pb.h"

namespace deform::client {

class ContactQuery {
 public:
  // Sends `start` on a new stream of `stub` (with `context`, credentials added) and waits for
  // `started`. The server's error (NOT_FOUND, INVALID_ARGUMENT, RESOURCE_EXHAUSTED...) otherwise,
  // and *query stays null.
  static grpc::Status Open(deform::v1::DeformService::Stub* stub,
                           std::unique_ptr<grpc::ClientContext> context,
                           const deform::v1::ContactQueryStart& start,
                           std::unique_ptr<ContactQuery>* query);
  ~ContactQuery();
  ContactQuery(const ContactQuery&) = delete;
  ContactQuery& operator=(const ContactQuery&) = delete;

  // The contact of `tool` against the skin as it stands (the named Deform stream's latest frame,
  // or the rest pose), with the next sequence number. Blocks for one round trip. After an error
  // the stream has ended: every later call returns that error.
  grpc::Status Query(const deform::v1::ToolState& tool, deform::v1::ContactResult* result);
  // What the server answered the start with (the diagonal and stiffness of the force model).
  const deform::v1::ContactQueryStarted& started() const { return started_; }
  // Half-closes and returns the stream's final status (OK after a clean end).
  grpc::Status Close();

 private:
  ContactQuery(std::unique_ptr<grpc::ClientContext> context,
               std::unique_ptr<grpc::ClientReaderWriter<deform::v1::QueryContactRequest,
                                                        deform::v1::QueryContactResponse>>
                   stream);
  // The final status once a read or write failed.
  grpc::Status FinishAfterFailure();

  std::unique_ptr<grpc::ClientContext> context_;
  std::unique_ptr<
      grpc::ClientReaderWriter<deform::v1::QueryContactRequest, deform::v1::QueryContactResponse>>
      stream_;
  deform::v1::ContactQueryStarted started_;
  deform::v1::QueryContactRequest request_;
  deform::v1::QueryContactResponse response_;
  std::uint64_t sequence_ = 0;
  bool finished_ = false;
  grpc::Status final_status_;
};

}  // namespace deform::client
