// Internal to the client library: opens the DeformStream that DeformClient::OpenStream returns.
#pragma once

#include <memory>
#include <string>

#include "core/codec/frame_codec.h"
#include "deform_client.h"

namespace deform::client::internal {

// Starts a Deform call on `stub` and sends `start`. `decoder` decodes encoded frames into
// positions (null: frames must carry float32 positions). `stub` must outlive the stream.
std::unique_ptr<DeformStream> StartDeformStream(deform::v1::DeformService::Stub* stub,
                                                const ClientOptions& options,
                                                const deform::v1::DeformStart& start,
                                                DeformClient::StreamCallbacks callbacks,
                                                std::unique_ptr<codec::FrameDecoder> decoder);

// The decoder of a mesh's encoded frames from its GetMeshInfo (vertex_count; for predicted frames
// its rest positions and prediction weights); null when they do not fit together.
std::unique_ptr<codec::FrameDecoder> MakeFrameDecoder(const deform::v1::GetMeshInfoResponse& info);

// positions (float32 bytes) = the decoded `encoded` frame.
grpc::Status DecodeFrame(const deform::v1::EncodedPositions& encoded, codec::FrameDecoder* decoder,
                         std::string* positions);

}  // namespace deform::client::internal
