// Decoding the compact frame encodings (core/codec) into the float32 positions callbacks get.
#include <cstring>
#include <string>
#include <utility>
#include <vector>

#include "deform_stream_impl.h"

namespace deform::client::internal {

std::unique_ptr<codec::FrameDecoder> MakeFrameDecoder(const deform::v1::GetMeshInfoResponse& info) {
  const int n = static_cast<int>(info.summary().vertex_count());
  auto decoder = std::make_unique<codec::FrameDecoder>(n);
  if (!info.has_prediction_weights()) return decoder;
  const deform::v1::PredictionWeights& proto = info.prediction_weights();
  const std::size_t slots = static_cast<std::size_t>(codec::kPredictionBonesPerVertex) * n;
  if (proto.bones().size() != 2 * slots || proto.weights().size() != 4 * slots ||
      info.rest_positions().size() != 12 * static_cast<std::size_t>(n)) {
    return nullptr;
  }
  codec::PredictionWeights weights;
  weights.bones.resize(slots);
  weights.weights.resize(slots);
  for (std::size_t s = 0; s < slots; ++s) {
    weights.bones[s] =
        static_cast<std::uint16_t>(static_cast<unsigned char>(proto.bones()[2 * s]) |
                                   (static_cast<unsigned char>(proto.bones()[2 * s + 1]) << 8));
  }
  std::memcpy(weights.weights.data(), proto.weights().data(), 4 * slots);  // little-endian hosts
  std::vector<float> rest(3 * static_cast<std::size_t>(n));
  std::memcpy(rest.data(), info.rest_positions().data(), 12 * static_cast<std::size_t>(n));
  if (!decoder
           ->SetPrediction(std::move(rest), std::move(weights), static_cast<int>(proto.num_bones()))
           .ok()) {
    return nullptr;
  }
  return decoder;
}

grpc::Status DecodeFrame(const deform::v1::EncodedPositions& encoded, codec::FrameDecoder* decoder,
                         std::string* positions) {
  if (decoder == nullptr) {
    return grpc::Status(grpc::StatusCode::INTERNAL,
                        "an encoded frame arrived but the stream has no decoder for it (its "
                        "mesh's GetMeshInfo failed or did not fit)");
  }
  codec::EncodedFrameHeader header;
  switch (encoded.encoding()) {
    case deform::v1::FRAME_ENCODING_QUANTIZED:
      header.encoding = codec::FrameEncoding::kQuantized;
      break;
    case deform::v1::FRAME_ENCODING_PREDICTED:
      header.encoding = codec::FrameEncoding::kPredicted;
      break;
    default:
      return grpc::Status(grpc::StatusCode::INTERNAL, "a frame in an unknown encoding");
  }
  if (header.encoding == codec::FrameEncoding::kQuantized && encoded.origin_size() != 3) {
    return grpc::Status(grpc::StatusCode::INTERNAL, "a quantized frame without its box origin");
  }
  for (int a = 0; a < encoded.origin_size() && a < 3; ++a) header.origin[a] = encoded.origin(a);
  header.step = encoded.step();
  header.max_error = encoded.max_error();
  const std::size_t values = 3 * static_cast<std::size_t>(decoder->num_vertices());
  positions->resize(4 * values);
  const Status decoded = decoder->Decode(
      header, reinterpret_cast<const unsigned char*>(encoded.data().data()), encoded.data().size(),
      encoded.bone_transforms().data(), static_cast<std::size_t>(encoded.bone_transforms_size()),
      reinterpret_cast<float*>(positions->data()));
  if (!decoded.ok()) return grpc::Status(grpc::StatusCode::INTERNAL, decoded.message());
  return grpc::Status::OK;
}

}  // namespace deform::client::internal
