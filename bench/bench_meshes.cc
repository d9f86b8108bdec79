#include "bench/bench_meshes.h"

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <map>

#include "core/constraints/bone_reach.h"
#include "core/io/model_input.h"
#include "core/io/phantom.h"

namespace deform::bench {
namespace {

std::map<std::string, std::shared_ptr<const DeformationModel>> g_models;
std::map<std::string, BonedModel> g_boned_models;

}  // namespace

std::shared_ptr<const DeformationModel> ModelFor(const BenchMesh& mesh, RotationBlend blend) {
  const std::string key = mesh.name + (blend == RotationBlend::kLinear ? "/linear" : "");
  auto it = g_models.find(key);
  if (it != g_models.end()) return it->second;
  auto input = LoadModelInput(mesh.mesh_path, mesh.skeleton_path, mesh.phantom_vertices);
  if (!input.ok()) return nullptr;
  ModelOptions options = ModelOptions::Paper();
  options.rotation_blend = blend;
  auto model = DeformationModel::Build(input->mesh, input->skeleton, options);
  if (!model.ok()) return nullptr;
  return g_models[key] = *model;
}

BonedModel BonedModelFor(const BenchMesh& mesh) {
  auto it = g_boned_models.find(mesh.name);
  if (it != g_boned_models.end()) return it->second;
  auto input = LoadModelInput(mesh.mesh_path, mesh.skeleton_path, mesh.phantom_vertices);
  if (!input.ok()) return {};
  BonedModel boned;
  boned.surfaces =
      input->bones.empty() ? MakeCapsuleBoneSurfaces(input->mesh, input->skeleton) : input->bones;
  ModelOptions options = ModelOptions::Paper();
  if (!UnanchorReachedSkin(input->mesh, input->skeleton, boned.surfaces, ConstraintOptions{},
                           &options)
           .ok()) {
    return {};
  }
  auto model = DeformationModel::Build(input->mesh, input->skeleton, options);
  if (!model.ok()) return {};
  boned.model = *model;
  return g_boned_models[mesh.name] = boned;
}

namespace {

std::string SharedDataDir() {
  return std::getenv("DEFORM_SHARED_DATA") ? std::getenv("DEFORM_SHARED_DATA")
                                           : DEFORM_SHARED_DATA_DIR;
}

}  // namespace

std::vector<BenchMesh> FactorizationScalingMeshes() {
  const std::string data = SharedDataDir();
  std::vector<BenchMesh> meshes;
  const BenchMesh arm{"arm_8311", data + "/arm/arm_8311.obj", data + "/arm/arm.tgf", "2:z:-60",
                      "2:z:-"};
  if (std::filesystem::exists(arm.mesh_path)) meshes.push_back(arm);
  for (const int vertices : {20'000, 200'000}) {
    BenchMesh phantom{"phantom_" + std::to_string(vertices / 1000) + "k", "", "", "knee:flexion:60",
                      "knee:flexion:"};
    phantom.phantom_vertices = vertices;
    meshes.push_back(phantom);
  }
  return meshes;
}

std::vector<BenchMesh> AvailableMeshes() {
  const std::string data = SharedDataDir();
  std::vector<BenchMesh> meshes = {{"phantom_2k", "", "", "knee:flexion:60", "knee:flexion:"}};
  const std::vector<BenchMesh> shared = {
      {"leg_1633", data + "/leg/leg_1633.obj", data + "/leg/leg.tgf", "1:x:60", "1:x:"},
      {"leg_25969", data + "/leg/leg_25969.obj", data + "/leg/leg.tgf", "1:x:60", "1:x:"},
      {"arm_132946", data + "/arm/arm_132946.obj", data + "/arm/arm.tgf", "2:z:-60", "2:z:-"},
  };
  for (const auto& m : shared) {
    if (std::filesystem::exists(m.mesh_path)) {
      meshes.push_back(m);
    } else {
      std::fprintf(stderr, "shared mesh %s absent; skipping its benchmarks\n", m.mesh_path.c_str());
    }
  }
  return meshes;
}

Pose PoseFromSpecOrRest(const DeformationModel& model, const std::string& spec) {
  Pose pose = Pose::Rest(model.skeleton());
  auto terms = ParsePoseSpec(spec, model.skeleton());
  if (terms.ok()) (void)PoseFromTerms(model.skeleton(), *terms, &pose);
  return pose;
}

}  // namespace deform::bench
