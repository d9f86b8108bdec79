// The compact frame encodings (core/codec) as a Deform stream and GetMeshInfo use them: the
// prediction weights of a mesh (its model's rotation field, the four largest weights per vertex,
// in the client's vertex order), the encoder a DeformStart asks for, and the bone transforms a
// predicted frame carries.
#pragma once

#include <memory>
#include <vector>

#include "core/base/status.h"
#include "core/codec/frame_codec.h"
#include "core/geometry/pose.h"
#include "deform/v1/deform.pb.h"
#include "service/registry/mesh_registry.h"

namespace deform::service {

// The largest error a client may ask of predicted frames, as a fraction of the bounding-box
// diagonal (the default: codec::kDefaultPredictedMaxError).
constexpr double kLargestPredictedMaxError = 1e-2;

// The mesh's prediction weights in the client's vertex order.
codec::PredictionWeights PredictionWeightsOf(const MeshEntry& entry);

// GetMeshInfo's prediction_weights.
void FillPredictionWeights(const MeshEntry& entry, v1::PredictionWeights* weights);

// The encoder `start` asks for: null for float32 frames. INVALID_ARGUMENT for an unknown encoding
// or a max_error outside (0, kLargestPredictedMaxError].
StatusOr<std::unique_ptr<codec::FrameEncoder>> MakeFrameEncoder(const v1::DeformStart& start,
                                                                const MeshEntry& entry);

// out[12 k .. 12 k + 11] = bone k's transform as float32 row-major [R | t]. No allocation.
void BoneTransformsAsFloats(const std::vector<RigidTransform>& bones, float* out);

}  // namespace deform::service
