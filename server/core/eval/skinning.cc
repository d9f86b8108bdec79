#include "core/eval/skinning.h"

namespace deform {

void LinearBlendSkinning(const Positions& rest, const BoneWeights& weights,
                         const std::vector<RigidTransform>& bone_transforms, Positions* posed) {
  posed->resize(rest.rows(), 3);
  for (int i = 0; i < rest.rows(); ++i) {
    const Eigen::Vector3d v = rest.row(i).transpose();
    Eigen::Vector3d x = Eigen::Vector3d::Zero();
    for (int p = weights.offsets[i]; p < weights.offsets[i + 1]; ++p) {
      x += weights.weights[p] * bone_transforms[weights.bones[p]].Apply(v);
    }
    posed->row(i) = x.transpose();
  }
}

void DualQuaternionSkinning(const Positions& rest, const BoneWeights& weights,
                            const std::vector<RigidTransform>& bone_transforms, Positions* posed) {
  // A rigid transform as a unit dual quaternion: real part q, dual part 0.5 * (0, t) * q.
  std::vector<Eigen::Quaterniond> real(bone_transforms.size()), dual(bone_transforms.size());
  for (size_t k = 0; k < bone_transforms.size(); ++k) {
    real[k] = bone_transforms[k].rotation.normalized();
    const Eigen::Vector3d& t = bone_transforms[k].translation;
    const Eigen::Quaterniond tq(0, t.x(), t.y(), t.z());
    dual[k].coeffs() = 0.5 * (tq * real[k]).coeffs();
  }
  posed->resize(rest.rows(), 3);
  for (int i = 0; i < rest.rows(); ++i) {
    Eigen::Vector4d b0 = Eigen::Vector4d::Zero(), be = Eigen::Vector4d::Zero();
    const Eigen::Quaterniond& pivot = real[weights.bones[weights.offsets[i]]];
    for (int p = weights.offsets[i]; p < weights.offsets[i + 1]; ++p) {
      const int k = weights.bones[p];
      const double w = pivot.dot(real[k]) < 0 ? -weights.weights[p] : weights.weights[p];
      b0 += w * real[k].coeffs();
      be += w * dual[k].coeffs();
    }
    const double norm = b0.norm();
    const Eigen::Quaterniond q0(Eigen::Vector4d(b0 / norm));
    const Eigen::Quaterniond qe(Eigen::Vector4d(be / norm));
    // Translation t = 2 * qe * conj(q0) (vector part).
    const Eigen::Quaterniond tq = qe * q0.conjugate();
    const Eigen::Vector3d t = 2.0 * tq.vec();
    posed->row(i) = (q0 * Eigen::Vector3d(rest.row(i).transpose()) + t).transpose();
  }
}

}  // namespace deform
