#include "loadtest/load_plan.h"

namespace deform::loadtest {

deform::v1::StiffnessUpdate SoftWeightUpdate(const std::string& joint, double soft) {
  deform::v1::StiffnessUpdate update;
  deform::v1::JointMaterialUpdate* material_update = update.add_joint_materials();
  material_update->set_joint(joint);
  deform::v1::JointMaterial* material = material_update->mutable_material();
  material->set_rigid(2.0);
  material->set_soft(soft);
  material->set_seam(4.0);
  return update;
}

}  // namespace deform::loadtest
