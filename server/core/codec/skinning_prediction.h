// The prediction of the predicted frame encoding: four-bone linear blend skinning in float32,
// specified operation by operation so that every decoder (C++, Python, the browser) computes the
// same bits as the encoder.
//
// For vertex i with rest position v (float32 x, y, z), bones b_0..b_3 and weights w_0..w_3
// (float32, summing to 1; unused slots have weight 0 and bone 0), and per bone a float32 3 x 4
// matrix M = [R | t] (row-major: M[0..3] is the first row), the prediction p is, in float32 with
// every operation rounded (no fused multiply-add):
//
//   p = (0, 0, 0)
//   for j in 0..3:            (in this order, also when w_j = 0)
//     M = transforms[b_j]
//     for a in x, y, z (row r = 0, 1, 2):
//       s = M[4r] * v.x
//       s = s + M[4r + 1] * v.y
//       s = s + M[4r + 2] * v.z
//       s = s + M[4r + 3]
//       p[r] = p[r] + w_j * s
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

namespace deform::codec {

constexpr int kPredictionBonesPerVertex = 4;
constexpr int kFloatsPerBoneTransform = 12;

// Per vertex, four bones and their weights (4 n each).
struct PredictionWeights {
  std::vector<std::uint16_t> bones;
  std::vector<float> weights;
  int num_vertices() const { return static_cast<int>(bones.size()) / kPredictionBonesPerVertex; }
};

// The prediction weights of a skinning given per vertex as lists (vertex i's bones and weights at
// [offsets[i], offsets[i + 1]), largest weight first, as the model's BoneWeights holds them), in
// the vertex order `order` (frame vertex c is vertex order[c]; empty: the same order): the four
// largest of each vertex, renormalized to sum to 1.
PredictionWeights TopFourWeights(const std::vector<int>& offsets, const std::vector<int>& bones,
                                 const std::vector<double>& weights, const std::vector<int>& order);

// predicted (3 n floats) = the prediction of every vertex. `rest` holds 3 n floats, `transforms`
// 12 per bone. Bones out of range are the caller's error (decoders check them first:
// CheckPredictionWeights). No allocation.
void PredictPositions(const float* rest, const PredictionWeights& weights, const float* transforms,
                      float* predicted);

// False when a bone index is >= num_bones or a weight is negative or not finite.
bool CheckPredictionWeights(const PredictionWeights& weights, int num_bones);

}  // namespace deform::codec
