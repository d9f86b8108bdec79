// Compact frames: each encoding decodes within its stated error, the prediction is bit-exact
// between encoder and decoder, a residual too large falls back to quantization, and malformed
// input is refused.
#include "core/codec/frame_codec.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

namespace deform::codec {
namespace {

// A bent tube of `n` vertices (double, solved order) around two bones.
std::vector<double> BentTube(int n, double angle) {
  std::vector<double> x(3 * n);
  for (int i = 0; i < n; ++i) {
    const double t = static_cast<double>(i) / n, around = 37.0 * t;
    double px = 0.3 * std::cos(around), py = 4.0 * t - 2.0, pz = 0.3 * std::sin(around);
    if (py > 0) {  // the lower half turns about x by `angle`
      const double y = py * std::cos(angle) - pz * std::sin(angle);
      pz = py * std::sin(angle) + pz * std::cos(angle);
      py = y;
    }
    x[3 * i] = px;
    x[3 * i + 1] = py;
    x[3 * i + 2] = pz;
  }
  return x;
}

double LargestError(const std::vector<double>& solved, const std::vector<float>& decoded) {
  double worst = 0;
  for (std::size_t k = 0; k < solved.size(); ++k) {
    worst = std::max(worst, std::abs(solved[k] - static_cast<double>(decoded[k])));
  }
  return worst;
}

TEST(FrameCodec, QuantizedFramesDecodeWithinHalfAStep) {
  const int n = 3000;
  const std::vector<double> frame = BentTube(n, 1.2);
  FrameEncoder encoder(n);
  std::vector<unsigned char> bytes(encoder.max_encoded_bytes());
  EncodedFrameHeader header;
  const std::size_t size = encoder.Encode(frame.data(), {}, nullptr, &header, bytes.data());
  EXPECT_EQ(header.encoding, FrameEncoding::kQuantized);
  EXPECT_LT(size, 8u * n);  // smaller than the records themselves
  FrameDecoder decoder(n);
  std::vector<float> decoded(3 * n);
  ASSERT_TRUE(decoder.Decode(header, bytes.data(), size, nullptr, 0, decoded.data()).ok());
  EXPECT_LE(LargestError(frame, decoded), header.max_error * 1.0001 + 1e-6);
  EXPECT_GT(header.max_error, 0);
}

TEST(FrameCodec, FramesFollowTheGivenVertexOrder) {
  const int n = 100;
  const std::vector<double> solved = BentTube(n, 0.5);
  std::vector<int> order(n);
  for (int c = 0; c < n; ++c) order[c] = n - 1 - c;  // the client's order is reversed
  FrameEncoder encoder(n);
  std::vector<unsigned char> bytes(encoder.max_encoded_bytes());
  EncodedFrameHeader header;
  const std::size_t size = encoder.Encode(solved.data(), order, nullptr, &header, bytes.data());
  FrameDecoder decoder(n);
  std::vector<float> decoded(3 * n);
  ASSERT_TRUE(decoder.Decode(header, bytes.data(), size, nullptr, 0, decoded.data()).ok());
  for (int c = 0; c < n; ++c) {
    EXPECT_NEAR(decoded[3 * c + 1], solved[3 * order[c] + 1], header.max_error * 1.0001 + 1e-6);
  }
}

// Two bones: the upper half follows bone 0 (identity), the lower half bone 1 (turned), with a
// blend in between; the frame is that skinning plus a small smooth displacement, as the method's
// frames are near their skinning.
struct PredictedCase {
  std::vector<float> rest;
  PredictionWeights weights;
  std::vector<float> transforms;
  std::vector<double> frame;
};

PredictedCase MakePredictedCase(int n, double angle) {
  PredictedCase c;
  const std::vector<double> rest = BentTube(n, 0.0);
  c.rest.assign(rest.begin(), rest.end());
  const float cs = static_cast<float>(std::cos(angle)), sn = static_cast<float>(std::sin(angle));
  c.transforms = {1, 0, 0, 0, 0, 1,  0,   0, 0, 0,  1,  0,   // bone 0
                  1, 0, 0, 0, 0, cs, -sn, 0, 0, sn, cs, 0};  // bone 1
  c.frame.resize(3 * n);
  for (int i = 0; i < n; ++i) {
    const float y = c.rest[3 * i + 1];
    const float h = std::clamp((y + 0.5f) / 1.0f, 0.0f, 1.0f);  // weight of bone 1
    c.weights.bones.insert(c.weights.bones.end(), {0, 1, 0, 0});
    c.weights.weights.insert(c.weights.weights.end(), {1 - h, h, 0, 0});
  }
  std::vector<float> predicted(3 * n);
  PredictPositions(c.rest.data(), c.weights, c.transforms.data(), predicted.data());
  for (int k = 0; k < 3 * n; ++k) c.frame[k] = predicted[k] + 0.01 * std::sin(0.37 * k);
  return c;
}

TEST(FrameCodec, PredictedFramesDecodeWithinHalfAStepAndAreSmaller) {
  const int n = 3000;
  PredictedCase c = MakePredictedCase(n, 1.3);
  const double step = 1e-4;
  FrameEncoder predicted_encoder(c.rest, c.weights, 2, step);
  std::vector<unsigned char> bytes(predicted_encoder.max_encoded_bytes());
  EncodedFrameHeader header;
  const std::size_t size =
      predicted_encoder.Encode(c.frame.data(), {}, c.transforms.data(), &header, bytes.data());
  ASSERT_EQ(header.encoding, FrameEncoding::kPredicted);
  EXPECT_DOUBLE_EQ(header.max_error, step / 2);
  FrameDecoder decoder(n);
  ASSERT_TRUE(decoder.SetPrediction(c.rest, c.weights, 2).ok());
  std::vector<float> decoded(3 * n);
  ASSERT_TRUE(decoder
                  .Decode(header, bytes.data(), size, c.transforms.data(), c.transforms.size(),
                          decoded.data())
                  .ok());
  EXPECT_LE(LargestError(c.frame, decoded), step / 2 * 1.0001 + 1e-6);
  // The same frame quantized in its box takes more bytes.
  FrameEncoder quantized_encoder(n);
  std::vector<unsigned char> quantized(quantized_encoder.max_encoded_bytes());
  EncodedFrameHeader quantized_header;
  EXPECT_LT(size, quantized_encoder.Encode(c.frame.data(), {}, nullptr, &quantized_header,
                                           quantized.data()));
}

TEST(FrameCodec, AResidualTooLargeFallsBackToQuantization) {
  const int n = 500;
  PredictedCase c = MakePredictedCase(n, 0.7);
  c.frame[0] += 10.0;  // 1e5 steps away from its prediction
  FrameEncoder encoder(c.rest, c.weights, 2, 1e-4);
  std::vector<unsigned char> bytes(encoder.max_encoded_bytes());
  EncodedFrameHeader header;
  const std::size_t size =
      encoder.Encode(c.frame.data(), {}, c.transforms.data(), &header, bytes.data());
  EXPECT_EQ(header.encoding, FrameEncoding::kQuantized);
  FrameDecoder decoder(n);
  std::vector<float> decoded(3 * n);
  ASSERT_TRUE(decoder.Decode(header, bytes.data(), size, nullptr, 0, decoded.data()).ok());
  EXPECT_LE(LargestError(c.frame, decoded), header.max_error * 1.0001 + 1e-5);
}

TEST(FrameCodec, MalformedInputIsRefused) {
  const int n = 200;
  PredictedCase c = MakePredictedCase(n, 0.7);
  FrameEncoder encoder(c.rest, c.weights, 2, 1e-4);
  std::vector<unsigned char> bytes(encoder.max_encoded_bytes());
  EncodedFrameHeader header;
  const std::size_t size =
      encoder.Encode(c.frame.data(), {}, c.transforms.data(), &header, bytes.data());
  FrameDecoder decoder(n);
  std::vector<float> decoded(3 * n);
  // No prediction set.
  EXPECT_FALSE(
      decoder.Decode(header, bytes.data(), size, c.transforms.data(), 24, decoded.data()).ok());
  ASSERT_TRUE(decoder.SetPrediction(c.rest, c.weights, 2).ok());
  // Wrong transform count, truncated bytes, garbage, a bad step.
  EXPECT_FALSE(
      decoder.Decode(header, bytes.data(), size, c.transforms.data(), 12, decoded.data()).ok());
  EXPECT_FALSE(
      decoder.Decode(header, bytes.data(), size / 2, c.transforms.data(), 24, decoded.data()).ok());
  std::vector<unsigned char> garbage(size, 0xAB);
  EXPECT_FALSE(
      decoder
          .Decode(header, garbage.data(), garbage.size(), c.transforms.data(), 24, decoded.data())
          .ok());
  EncodedFrameHeader bad = header;
  bad.step = std::nan("");
  EXPECT_FALSE(
      decoder.Decode(bad, bytes.data(), size, c.transforms.data(), 24, decoded.data()).ok());
  // Weights naming a bone the frames do not carry.
  PredictionWeights wrong = c.weights;
  wrong.bones[5] = 7;
  EXPECT_FALSE(FrameDecoder(n).SetPrediction(c.rest, wrong, 2).ok());
}

}  // namespace
}  // namespace deform::codec
