#include "service/messages/frame_encoding.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <string>
#include <utility>

#include "service/messages/proto_conversion.h"

namespace deform::service {
namespace {

std::vector<float> RestInClientOrder(const MeshEntry& entry) {
  const TriangleMesh& mesh = entry.model->mesh();
  std::vector<float> rest(3 * static_cast<std::size_t>(entry.client_vertex_count()));
  EncodeInClientOrder(mesh.vertices.data(), mesh.num_vertices(),
                      entry.file_metadata.file_vertex_to_mesh,
                      reinterpret_cast<char*>(rest.data()));
  return rest;
}

}  // namespace

codec::PredictionWeights PredictionWeightsOf(const MeshEntry& entry) {
  const BoneWeights& bw = entry.model->bone_weights();
  return codec::TopFourWeights(bw.offsets, bw.bones, bw.weights,
                               entry.file_metadata.file_vertex_to_mesh);
}

void FillPredictionWeights(const MeshEntry& entry, v1::PredictionWeights* proto) {
  const codec::PredictionWeights weights = PredictionWeightsOf(entry);
  std::string* bones = proto->mutable_bones();
  bones->resize(weights.bones.size() * 2);
  for (std::size_t s = 0; s < weights.bones.size(); ++s) {
    (*bones)[2 * s] = static_cast<char>(weights.bones[s] & 0xFF);
    (*bones)[2 * s + 1] = static_cast<char>(weights.bones[s] >> 8);
  }
  std::string* values = proto->mutable_weights();
  values->resize(weights.weights.size() * 4);
  std::memcpy(values->data(), weights.weights.data(), values->size());  // little-endian hosts
  proto->set_num_bones(static_cast<std::uint32_t>(entry.model->skeleton().num_bones()));
}

StatusOr<std::unique_ptr<codec::FrameEncoder>> MakeFrameEncoder(const v1::DeformStart& start,
                                                                const MeshEntry& entry) {
  switch (start.encoding()) {
    case v1::FRAME_ENCODING_UNSPECIFIED:
    case v1::FRAME_ENCODING_FLOAT32:
      return std::unique_ptr<codec::FrameEncoder>();
    case v1::FRAME_ENCODING_QUANTIZED:
      return std::make_unique<codec::FrameEncoder>(entry.client_vertex_count());
    case v1::FRAME_ENCODING_PREDICTED:
      break;
    default:
      return Status::InvalidArgument("unknown frame encoding " +
                                     std::to_string(static_cast<int>(start.encoding())));
  }
  double max_error = start.max_error() == 0 ? codec::kDefaultPredictedMaxError : start.max_error();
  if (!(max_error > 0 && max_error <= kLargestPredictedMaxError)) {
    return Status::InvalidArgument("max_error must be in (0, " +
                                   std::to_string(kLargestPredictedMaxError) +
                                   "] of the diagonal, or 0 for the default");
  }
  const double step = 2 * max_error * entry.model->bounding_box_diagonal();
  return std::make_unique<codec::FrameEncoder>(RestInClientOrder(entry), PredictionWeightsOf(entry),
                                               entry.model->skeleton().num_bones(), step);
}

void BoneTransformsAsFloats(const std::vector<RigidTransform>& bones, float* out) {
  for (std::size_t k = 0; k < bones.size(); ++k) {
    const Eigen::Matrix3d r = bones[k].rotation.toRotationMatrix();
    float* m = out + codec::kFloatsPerBoneTransform * k;
    for (int row = 0; row < 3; ++row) {
      for (int col = 0; col < 3; ++col) m[4 * row + col] = static_cast<float>(r(row, col));
      m[4 * row + 3] = static_cast<float>(bones[k].translation[row]);
    }
  }
}

}  // namespace deform::service
