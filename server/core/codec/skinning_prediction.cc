#include "core/codec/skinning_prediction.h"

#include <algorithm>
#include <cmath>

namespace deform::codec {

void PredictPositions(const float* rest, const PredictionWeights& weights, const float* transforms,
                      float* predicted) {
  const int n = weights.num_vertices();
  for (int i = 0; i < n; ++i) {
    const float vx = rest[3 * i], vy = rest[3 * i + 1], vz = rest[3 * i + 2];
    float p[3] = {0.0f, 0.0f, 0.0f};
    for (int j = 0; j < kPredictionBonesPerVertex; ++j) {
      const int slot = kPredictionBonesPerVertex * i + j;
      const float w = weights.weights[slot];
      const float* m = transforms + kFloatsPerBoneTransform * weights.bones[slot];
      for (int r = 0; r < 3; ++r) {
        float s = m[4 * r] * vx;
        s = s + m[4 * r + 1] * vy;
        s = s + m[4 * r + 2] * vz;
        s = s + m[4 * r + 3];
        p[r] = p[r] + w * s;
      }
    }
    predicted[3 * i] = p[0];
    predicted[3 * i + 1] = p[1];
    predicted[3 * i + 2] = p[2];
  }
}

PredictionWeights TopFourWeights(const std::vector<int>& offsets, const std::vector<int>& bones,
                                 const std::vector<double>& weights,
                                 const std::vector<int>& order) {
  const int n =
      order.empty() ? static_cast<int>(offsets.size()) - 1 : static_cast<int>(order.size());
  constexpr int kSlots = kPredictionBonesPerVertex;
  PredictionWeights result;
  result.bones.assign(static_cast<std::size_t>(kSlots) * n, 0);
  result.weights.assign(static_cast<std::size_t>(kSlots) * n, 0.0f);
  for (int c = 0; c < n; ++c) {
    const int i = order.empty() ? c : order[c];
    const int begin = offsets[i];
    const int count = std::min(kSlots, offsets[i + 1] - begin);
    double sum = 0;
    for (int j = 0; j < count; ++j) sum += weights[begin + j];
    for (int j = 0; j < count; ++j) {
      result.bones[kSlots * c + j] = static_cast<std::uint16_t>(bones[begin + j]);
      result.weights[kSlots * c + j] = static_cast<float>(weights[begin + j] / sum);
    }
  }
  return result;
}

bool CheckPredictionWeights(const PredictionWeights& weights, int num_bones) {
  if (weights.bones.size() != weights.weights.size() ||
      weights.bones.size() % kPredictionBonesPerVertex != 0) {
    return false;
  }
  for (std::size_t s = 0; s < weights.bones.size(); ++s) {
    if (weights.bones[s] >= num_bones) return false;
    if (!std::isfinite(weights.weights[s]) || weights.weights[s] < 0) return false;
  }
  return true;
}

}  // namespace deform::codec
