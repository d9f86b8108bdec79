#include "core/codec/frame_codec.h"

#include <meshoptimizer.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <utility>

namespace deform::codec {
namespace {

constexpr std::size_t kRecordBytes = 8;  // uint16 x, y, z, 0
constexpr double kQuantizedLevels = 65535.0;
constexpr int kLargestResidual = 32767;

std::uint16_t ZigZag(int r) {
  return static_cast<std::uint16_t>((static_cast<unsigned>(r) << 1) ^ (r < 0 ? 0xFFFFu : 0u));
}
int UnZigZag(std::uint16_t z) { return (z >> 1) ^ -static_cast<int>(z & 1); }

const double* Vertex(const double* solution, const std::vector<int>& order, int c) {
  return solution + 3 * static_cast<std::size_t>(order.empty() ? c : order[c]);
}

}  // namespace

FrameEncoder::FrameEncoder(int num_vertices)
    : num_vertices_(num_vertices),
      max_encoded_bytes_(meshopt_encodeVertexBufferBound(num_vertices, kRecordBytes)),
      records_(4 * static_cast<std::size_t>(num_vertices), 0) {}

FrameEncoder::FrameEncoder(std::vector<float> rest, PredictionWeights weights, int num_bones,
                           double step)
    : FrameEncoder(weights.num_vertices()) {
  rest_ = std::move(rest);
  weights_ = std::move(weights);
  num_bones_ = num_bones;
  step_ = step;
  predicted_.resize(rest_.size());
}

std::size_t FrameEncoder::EncodeQuantized(const double* solution, const std::vector<int>& order,
                                          EncodedFrameHeader* header, unsigned char* out) {
  double lo[3], hi[3];
  for (int a = 0; a < 3; ++a) {
    lo[a] = std::numeric_limits<double>::infinity();
    hi[a] = -lo[a];
  }
  for (int c = 0; c < num_vertices_; ++c) {
    const double* x = Vertex(solution, order, c);
    for (int a = 0; a < 3; ++a) {
      lo[a] = std::min(lo[a], x[a]);
      hi[a] = std::max(hi[a], x[a]);
    }
  }
  double extent = 0;
  for (int a = 0; a < 3; ++a) extent = std::max(extent, hi[a] - lo[a]);
  const double step = extent > 0 ? extent / kQuantizedLevels : 1.0;
  for (int c = 0; c < num_vertices_; ++c) {
    const double* x = Vertex(solution, order, c);
    for (int a = 0; a < 3; ++a) {
      const double q = std::round((x[a] - lo[a]) / step);
      records_[4 * c + a] = static_cast<std::uint16_t>(std::clamp(q, 0.0, kQuantizedLevels));
    }
  }
  header->encoding = FrameEncoding::kQuantized;
  for (int a = 0; a < 3; ++a) header->origin[a] = num_vertices_ > 0 ? lo[a] : 0.0;
  header->step = step;
  header->max_error = step / 2;
  return meshopt_encodeVertexBuffer(out, max_encoded_bytes_, records_.data(), num_vertices_,
                                    kRecordBytes);
}

bool FrameEncoder::QuantizeResidual(const double* solution, const std::vector<int>& order) {
  for (int c = 0; c < num_vertices_; ++c) {
    const double* x = Vertex(solution, order, c);
    for (int a = 0; a < 3; ++a) {
      const double r = std::round((x[a] - predicted_[3 * c + a]) / step_);
      if (!(std::abs(r) <= kLargestResidual)) return false;
      records_[4 * c + a] = ZigZag(static_cast<int>(r));
    }
  }
  return true;
}

std::size_t FrameEncoder::Encode(const double* solution, const std::vector<int>& order,
                                 const float* transforms, EncodedFrameHeader* header,
                                 unsigned char* out) {
  if (!predicted()) return EncodeQuantized(solution, order, header, out);
  PredictPositions(rest_.data(), weights_, transforms, predicted_.data());
  if (!QuantizeResidual(solution, order)) return EncodeQuantized(solution, order, header, out);
  header->encoding = FrameEncoding::kPredicted;
  header->origin[0] = header->origin[1] = header->origin[2] = 0;
  header->step = step_;
  header->max_error = step_ / 2;
  return meshopt_encodeVertexBuffer(out, max_encoded_bytes_, records_.data(), num_vertices_,
                                    kRecordBytes);
}

FrameDecoder::FrameDecoder(int num_vertices)
    : num_vertices_(num_vertices), records_(4 * static_cast<std::size_t>(num_vertices), 0) {}

Status FrameDecoder::SetPrediction(std::vector<float> rest, PredictionWeights weights,
                                   int num_bones) {
  if (weights.num_vertices() != num_vertices_ ||
      rest.size() != 3 * static_cast<std::size_t>(num_vertices_)) {
    return Status::InvalidArgument("prediction weights or rest positions for " +
                                   std::to_string(weights.num_vertices()) +
                                   " vertices; frames have " + std::to_string(num_vertices_));
  }
  if (!CheckPredictionWeights(weights, num_bones)) {
    return Status::InvalidArgument("prediction weights name a bone out of range or are negative");
  }
  rest_ = std::move(rest);
  weights_ = std::move(weights);
  num_bones_ = num_bones;
  predicted_.assign(rest_.size(), 0.0f);
  return Status::Ok();
}

Status FrameDecoder::Decode(const EncodedFrameHeader& header, const unsigned char* data,
                            std::size_t size, const float* transforms, std::size_t transform_floats,
                            float* positions) {
  if (!std::isfinite(header.step) || header.step <= 0) {
    return Status::InvalidArgument("encoded frame's step must be positive and finite");
  }
  if (meshopt_decodeVertexBuffer(records_.data(), num_vertices_, kRecordBytes, data, size) != 0) {
    return Status::InvalidArgument("encoded frame's bytes do not decode to " +
                                   std::to_string(num_vertices_) + " vertices");
  }
  if (header.encoding == FrameEncoding::kQuantized) {
    for (int c = 0; c < num_vertices_; ++c) {
      for (int a = 0; a < 3; ++a) {
        positions[3 * c + a] =
            static_cast<float>(header.origin[a] + records_[4 * c + a] * header.step);
      }
    }
    return Status::Ok();
  }
  if (header.encoding != FrameEncoding::kPredicted) {
    return Status::InvalidArgument("unknown frame encoding");
  }
  if (rest_.empty() && num_vertices_ > 0) {
    return Status::InvalidArgument("a predicted frame needs the mesh's prediction weights");
  }
  if (transform_floats != static_cast<std::size_t>(kFloatsPerBoneTransform) * num_bones_) {
    return Status::InvalidArgument("a predicted frame needs " +
                                   std::to_string(kFloatsPerBoneTransform * num_bones_) +
                                   " transform floats, got " + std::to_string(transform_floats));
  }
  PredictPositions(rest_.data(), weights_, transforms, predicted_.data());
  for (int c = 0; c < num_vertices_; ++c) {
    for (int a = 0; a < 3; ++a) {
      positions[3 * c + a] =
          static_cast<float>(predicted_[3 * c + a] + UnZigZag(records_[4 * c + a]) * header.step);
    }
  }
  return Status::Ok();
}

}  // namespace deform::codec
