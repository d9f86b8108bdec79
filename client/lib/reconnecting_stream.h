// Internal to the client library: the DeformStream that ReconnectPolicy (deform_client.h) gives,
// over a succession of plain streams to the same mesh.
#pragma once

#include <functional>
#include <memory>

#include "deform_client.h"

namespace deform::client::internal {

// Opens one plain stream with these callbacks; null when it could not even start (the attempt
// counts as failed and is retried after the backoff).
using StreamOpener =
    std::function<std::unique_ptr<DeformStream>(DeformClient::StreamCallbacks callbacks)>;

std::unique_ptr<DeformStream> StartReconnectingStream(StreamOpener open,
                                                      DeformClient::StreamCallbacks callbacks,
                                                      const ReconnectPolicy& policy);

// The server's advised retry delay (google.rpc.RetryInfo in the status details), in
// milliseconds; 0 when it gives none.
int RetryDelayMs(const grpc::Status& status);

}  // namespace deform::client::internal
