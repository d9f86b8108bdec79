#include "service/load/mesh_loader.h"

#include <spdlog/spdlog.h>

#include <utility>

#include "core/constraints/bone_reach.h"
#include "service/base/log_text.h"
#include "service/base/request_limits.h"

namespace deform::service {
namespace {

double MillisecondsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
      .count();
}

// "double", "float32, rest pose within 1.4e-07 of the diagonal", or why it stayed double.
std::string FactorPrecisionText(const DeformationModel& model) {
  const MaterialFactorization& factorization = *model.default_factorization();
  if (factorization.factor().stores_float32()) {
    return fmt::format("float32, rest pose within {:.1e} of the diagonal",
                       factorization.float32_probe_error());
  }
  if (factorization.float32_probe_error() >= 0) {
    return fmt::format("double: float32 would move the rest pose by {:.1e} of the diagonal",
                       factorization.float32_probe_error());
  }
  return "double";
}

// An estimate of what the constraints of a skin of `skin_vertices` hold with `surfaces`: per skin
// vertex its volume flags and a candidate entry per surface, per surface its mesh (24 bytes a
// vertex, 12 a triangle) and its search tree (a node and a copy of its triangle, about 150 bytes a
// triangle).
std::size_t EstimateConstraintBytes(int skin_vertices, const std::vector<BoneSurface>& surfaces) {
  const auto n = static_cast<std::size_t>(skin_vertices);
  std::size_t bytes = 4 * n;
  for (const BoneSurface& surface : surfaces) {
    bytes += 4 * n + 24 * static_cast<std::size_t>(surface.mesh.num_vertices()) +
             162 * static_cast<std::size_t>(surface.mesh.num_triangles());
  }
  return bytes;
}

// The constraints of `model`: its bone contacts (refusing a surface the rest skin enters, naming
// it) and the skin constraints over them. None when there is nothing to keep and no tool to take.
StatusOr<MeshConstraints> MakeConstraints(const DeformationModel& model,
                                          std::vector<BoneSurface> surfaces,
                                          const ConstraintOptions& options,
                                          const MeshLimits& limits) {
  MeshConstraints made;
  made.options = options;
  if (surfaces.empty() && !options.keep_volume && options.max_tool_contacts == 0) return made;
  made.bytes = EstimateConstraintBytes(model.mesh().num_vertices(), surfaces);
  std::shared_ptr<const BoneContacts> bones;
  if (!surfaces.empty()) {
    auto contacts = BoneContacts::Create(std::move(surfaces), model.skeleton(), model.mesh(),
                                         model.rigid_bones(), limits);
    if (!contacts.ok()) {
      return InField(contacts.status().WithContext("bone surfaces"), "upload.bone_surfaces");
    }
    bones = std::move(*contacts);
  }
  auto constraints = SkinConstraints::Create(model, std::move(bones), options);
  if (!constraints.ok()) {
    return InField(constraints.status().WithContext("options.constraints"), "options.constraints");
  }
  made.constraints = std::move(*constraints);
  // An open skin without bones, taking no tools.
  if (!made.constraints->active() && !made.constraints->takes_tools()) made.constraints = nullptr;
  return made;
}

std::string OnOff(bool on) { return on ? "on" : "off"; }

StatusOr<std::shared_ptr<const MeshEntry>> Build(ServiceContext* context, Admission::MeshSlot slot,
                                                 LoadJob job, const LoadProgress& progress) {
  job.options.limits.max_vertices = context->limits().max_vertices;
  job.options.float32_factor_min_bytes = context->solve_settings().float32_factor_min_bytes;
  const std::size_t bytes_before_build =
      DeformationModel::EstimateBytesBeforeBuild(job.mesh.num_vertices(),
                                                 job.mesh.num_triangles()) +
      EstimateConstraintBytes(job.mesh.num_vertices(), job.bone_surfaces);
  const int vertices = job.mesh.num_vertices();
  BuildHooks hooks;
  hooks.validated = [&] {
    DEFORM_RETURN_IF_ERROR(context->admission().ReserveMemory(
        &slot, bytes_before_build, "a mesh of " + std::to_string(vertices) + " vertices"));
    if (progress) progress(LoadStage::kValidated, MillisecondsSince(job.start));
    return Status::Ok();
  };
  hooks.cancel = job.cancel;
  hooks.precomputed = [&] {
    if (progress) progress(LoadStage::kWeights, MillisecondsSince(job.start));
  };
  DEFORM_RETURN_IF_ERROR(UnanchorReachedSkin(job.mesh, job.skeleton, job.bone_surfaces,
                                             job.constraints, &job.options, job.cancel));
  DEFORM_ASSIGN_OR_RETURN(
      std::shared_ptr<const DeformationModel> model,
      DeformationModel::Build(std::move(job.mesh), std::move(job.skeleton), job.options,
                              job.weights.has_value() ? &*job.weights : nullptr, hooks));
  MeshLimits mesh_limits;
  mesh_limits.max_vertices = context->limits().max_vertices;
  DEFORM_ASSIGN_OR_RETURN(
      MeshConstraints constraints,
      MakeConstraints(*model, std::move(job.bone_surfaces), job.constraints, mesh_limits));
  if (progress) progress(LoadStage::kFactorized, MillisecondsSince(job.start));
  MeshSolvePlan solve = PlanMeshSolve(*model, context->solve_settings());
  DEFORM_ASSIGN_OR_RETURN(
      std::shared_ptr<const MeshEntry> entry,
      context->registry().Register(std::move(slot), job.name, std::move(model),
                                   std::move(job.file_metadata), std::move(solve),
                                   std::move(job.id), std::move(constraints)));
  spdlog::info(
      "mesh={} tenant={} name='{}' loaded: {} vertices, precompute {:.1f} ms, factor {:.1f} ms "
      "({}), about {} KiB",
      entry->id, EscapeForLog(entry->tenant), EscapeForLog(entry->name), vertices,
      entry->precompute_ms, entry->factor_ms, FactorPrecisionText(*entry->model),
      entry->memory_bytes >> 10);
  std::string phases;
  for (const DeformationModel::BuildPhase& phase : entry->model->build_phases()) {
    phases +=
        fmt::format("{}{} {:.0f} ms", phases.empty() ? "" : ", ", phase.name, phase.seconds * 1e3);
  }
  spdlog::debug("mesh={} build phases: {}", entry->id, phases);
  std::string bones;
  if (const BoneContacts* contacts = entry->bones()) {
    for (int s = 0; s < contacts->num_surfaces(); ++s) {
      const BoneSurface& surface = contacts->surface(s);
      bones += fmt::format("{}'{}' on bone {} ({} triangles)", s > 0 ? ", " : "",
                           EscapeForLog(surface.name), surface.bone, surface.mesh.num_triangles());
    }
  }
  const ConstraintOptions& constraint_options = entry->constraints.options;
  spdlog::info("mesh={} constraints: contacts {}, volume {}, margin {:g}; bone surfaces: {}",
               entry->id, OnOff(constraint_options.contacts()),
               OnOff(constraint_options.keep_volume), constraint_options.contact_margin,
               bones.empty() ? "none" : bones);
  for (const std::string& warning : entry->model->binding_report().warnings) {
    spdlog::warn("mesh={} binding: {}", entry->id, EscapeForLog(warning));
  }
  if (!entry->file_metadata.unused_file_vertices.empty()) {
    spdlog::warn("mesh={} {} file vertices used by no triangle follow the used vertex before them",
                 entry->id, entry->file_metadata.unused_file_vertices.size());
  }
  return entry;
}

}  // namespace

StatusOr<std::shared_ptr<const MeshEntry>> BuildAndRegister(ServiceContext* context,
                                                            Admission::MeshSlot slot, LoadJob job,
                                                            const LoadProgress& progress) {
  const auto started = std::chrono::steady_clock::now();
  ServiceMetrics* metrics = job.metrics;
  StatusOr<std::shared_ptr<const MeshEntry>> entry =
      Build(context, std::move(slot), std::move(job), progress);
  if (metrics != nullptr) {
    metrics->BuildFinished(
        std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count(),
        entry.ok());
  }
  return entry;
}

}  // namespace deform::service
