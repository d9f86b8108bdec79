#include "core/codec/skinning_prediction.h"

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
