// Compact frames: positions quantized in a box, or predicted by linear blend skinning with a
// quantized residual, each coded by meshoptimizer's vertex codec (whose decoder also ships on npm,
// so browsers decode the same bytes).
//
// Both encodings quantize every coordinate with one step: the decoded coordinate differs from the
// solved one by at most step / 2 (the header's max_error), plus the float32 rounding of the decoded
// value. The bytes are meshopt_encodeVertexBuffer of 8-byte records, one per vertex in the frame's
// vertex order: four little-endian uint16 (x, y, z, 0).
//  - kQuantized: q = round((x - origin) / step) in [0, 65535], origin the frame's box's minimum
//    corner and step its largest extent / 65535; decoded x = float(origin + q * step) in double.
//  - kPredicted: r = round((x - p) / step) with p the float32 prediction (skinning_prediction.h) of
//    the frame's bone transforms, |r| <= 32767, stored zigzag-coded ((r << 1) ^ (r >> 15)); decoded
//    x = float(p + r * step) in double. A frame whose residual does not fit is sent kQuantized.
// Each frame stands alone: a skipped frame costs its decoder nothing.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "core/base/status.h"
#include "core/codec/skinning_prediction.h"

namespace deform::codec {

enum class FrameEncoding { kFloat32 = 1, kQuantized = 2, kPredicted = 3 };

// The largest per-coordinate error of kPredicted frames when a stream asks for none
// (DeformStart.max_error = 0), as a fraction of the mesh's bounding-box diagonal: such a stream's
// step is 2 x this x the diagonal. The one home of the default; the server, the benchmarks and the
// clients' help text read it.
inline constexpr double kDefaultPredictedMaxError = 5e-5;

// What a coded frame states besides its bytes.
struct EncodedFrameHeader {
  FrameEncoding encoding = FrameEncoding::kQuantized;
  double origin[3] = {0, 0, 0};  // kQuantized: the box's minimum corner
  double step = 0;               // the quantization step, model units
  double max_error = 0;          // step / 2: the largest per-coordinate error, model units
};

// Encodes one stream's frames. Buffers are sized at construction; Encode allocates nothing.
// Not thread-safe (one per stream).
class FrameEncoder {
 public:
  // kQuantized frames of `num_vertices` vertices.
  explicit FrameEncoder(int num_vertices);
  // kPredicted frames: `rest` (3 n float32) and `weights` in the frame's vertex order, `num_bones`
  // transforms per frame, residual quantized with `step` (model units, > 0).
  FrameEncoder(std::vector<float> rest, PredictionWeights weights, int num_bones, double step);

  // Bytes Encode may write at most.
  std::size_t max_encoded_bytes() const { return max_encoded_bytes_; }
  bool predicted() const { return !rest_.empty(); }

  // Codes the frame whose vertex c is solution[3 order[c] .. 3 order[c] + 2] (order empty: c
  // itself) into out[0, max_encoded_bytes()), filling `header`; returns the bytes written.
  // `transforms`: 12 floats per bone (skinning_prediction.h), read for kPredicted only.
  std::size_t Encode(const double* solution, const std::vector<int>& order, const float* transforms,
                     EncodedFrameHeader* header, unsigned char* out);

 private:
  std::size_t EncodeQuantized(const double* solution, const std::vector<int>& order,
                              EncodedFrameHeader* header, unsigned char* out);
  bool QuantizeResidual(const double* solution, const std::vector<int>& order);

  int num_vertices_ = 0;
  std::size_t max_encoded_bytes_ = 0;
  std::vector<std::uint16_t> records_;  // 4 per vertex
  std::vector<float> rest_;
  PredictionWeights weights_;
  int num_bones_ = 0;
  double step_ = 0;
  std::vector<float> predicted_;
};

// Decodes one stream's frames into float32 positions. Not thread-safe (one per stream).
class FrameDecoder {
 public:
  explicit FrameDecoder(int num_vertices);
  int num_vertices() const { return num_vertices_; }
  // What kPredicted frames need (the mesh's rest positions and prediction weights, in the frames'
  // vertex order). INVALID_ARGUMENT when the sizes do not match or a weight is unusable.
  Status SetPrediction(std::vector<float> rest, PredictionWeights weights, int num_bones);

  // positions (3 n floats) = the decoded frame. INVALID_ARGUMENT for malformed bytes, a
  // non-positive or non-finite step, a kPredicted frame without SetPrediction() or with the wrong
  // number of transform floats. No allocation after the first frame of each kind.
  Status Decode(const EncodedFrameHeader& header, const unsigned char* data, std::size_t size,
                const float* transforms, std::size_t transform_floats, float* positions);

 private:
  int num_vertices_ = 0;
  std::vector<std::uint16_t> records_;
  std::vector<float> rest_;
  PredictionWeights weights_;
  int num_bones_ = 0;
  std::vector<float> predicted_;
};

}  // namespace deform::codec
