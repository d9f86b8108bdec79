// Internal to the client library: opens the DeformStream that DeformClient::OpenStream returns.
#pragma once

#include <memory>
#include <string>

#include "deform_client.h"

namespace deform::client::internal {

// Starts a Deform call on `stub` and sends `start` for `mesh_id`. `stub` must outlive the stream.
std::unique_ptr<DeformStream> StartDeformStream(deform::v1::DeformService::Stub* stub,
                                                const ClientOptions& options,
                                                const std::string& mesh_id,
                                                DeformClient::StreamCallbacks callbacks);

}  // namespace deform::client::internal
