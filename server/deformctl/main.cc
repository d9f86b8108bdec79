// deformctl: the deformation core from the command line.
//
//   deformctl deform [--mesh FILE --skeleton FILE [--weights FILE] | --mesh RIG.glb] --pose SPEC
//                    [--method paper|paper-linear|laplacian|lbs|dqs|cor|ddm] [--out FILE]
//                    [--repeat N] [--joint-nodes on|off] [--material on|off]
//                    [--material-profile RIGID,SOFT,SEAM]
//                    [--laplacian uniform|cotangent|intrinsic]
//                    [--bone-surface FILE:BONE ...] [--bones input|capsules|none]
//                    [--contacts on|off] [--bone-reach on|off] [--volume on|off]
//                    [--out-bones DIR]
//                    [--tool sphere:X,Y,Z,R | capsule:X0,Y0,Z0,X1,Y1,Z1,R ...]
//                    [--rigid-weight-tolerance X]
//   deformctl phantom --out FILE [--skeleton-out FILE] [--vertices N]
//
// Prints one JSON object on stdout; errors are one line on stderr and a non-zero exit code.
#include <spdlog/spdlog.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <fstream>
#include <iostream>
#include <limits>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "core/base/build_info.h"
#include "core/base/text.h"
#include "core/constraints/bone_reach.h"
#include "core/constraints/skin_constraints.h"
#include "core/constraints/tools.h"
#include "core/eval/method_comparison.h"
#include "core/io/bone_surface_io.h"
#include "core/io/gltf_animation.h"
#include "core/io/mesh_io.h"
#include "core/io/model_input.h"
#include "core/io/phantom.h"
#include "core/io/rig_import.h"
#include "core/io/skeleton_io.h"

namespace {

using deform::Status;
using deform::StatusOr;

struct DeformArgs {
  std::string mesh_path;
  std::string skeleton_path;
  std::string weights_path;
  int phantom_vertices = deform::kDefaultPhantomVertices;
  std::string pose = "rest";
  std::string animation;  // a glTF animation's name or index: the pose at `time` of it
  double time = 0;
  std::string method = "paper";
  std::string out_path;
  int repeat = 1;
  double radius_factor = 1.5;
  std::string ordering = "auto";
  std::vector<std::string> bone_surfaces;  // FILE:BONE
  std::string bones = "input";
  bool contacts = true;
  bool volume = true;
  bool bone_reach = true;       // ModelOptions::unanchored_vertices from SkinReachedAcrossJoints
  int unanchored_vertices = 0;  // set once they are found
  int max_contacts = 0;         // the constraints' bound, set once they are made
  std::size_t constraint_scratch_bytes = 0;  // a stream's constraint scratch, likewise
  std::string out_bones_dir;
  std::vector<std::string> tools;  // ParseToolSpec's text
  int bone_surface_count = 0;      // set once they are loaded
  std::string joint_nodes = "on";  // off: ModelOptions::use_joint_nodes = false
  std::string material = "on";     // off: ModelOptions::uniform_material = true
  std::string material_profile;    // RIGID,SOFT,SEAM: ModelOptions::default_material
  std::string laplacian = "uniform";
  double rigid_weight_tolerance = deform::ModelOptions{}.rigid_weight_tolerance;
};

struct PhantomArgs {
  std::string out_path;
  std::string skeleton_out_path;
  int vertices = deform::kDefaultPhantomVertices;
};

int Fail(const Status& status) {
  std::cerr << "deformctl: " << status.ToString() << "\n";
  return 1;
}

// "RIGID,SOFT,SEAM" as a joint material, each weight checked by the material rule.
StatusOr<deform::JointMaterial> MaterialProfileFromText(const std::string& text) {
  const std::vector<std::string_view> fields = deform::Split(text, ',');
  double weights[3];
  for (std::size_t w = 0; w < 3; ++w) {
    if (fields.size() != 3 || !deform::ParseFiniteDouble(fields[w], &weights[w])) {
      return deform::Status::InvalidArgument(
          "--material-profile takes RIGID,SOFT,SEAM (three numbers), got '" + text + "'");
    }
  }
  const deform::JointMaterial material{weights[0], weights[1], weights[2]};
  DEFORM_RETURN_IF_ERROR(deform::CheckJointMaterial(material, "--material-profile"));
  return material;
}

// The paper's options with the command line's region radius factor, ordering, Laplacian weights
// and ablation switches (the joint nodes, the material weights).
StatusOr<deform::ModelOptions> ModelOptionsFrom(const DeformArgs& args) {
  deform::ModelOptions options = deform::ModelOptions::Paper();
  options.regions.radius_factor = args.radius_factor;
  options.use_joint_nodes = args.joint_nodes == "on";
  options.uniform_material = args.material == "off";
  if (!args.material_profile.empty()) {
    DEFORM_ASSIGN_OR_RETURN(options.default_material,
                            MaterialProfileFromText(args.material_profile));
  }
  options.rigid_weight_tolerance = args.rigid_weight_tolerance;
  DEFORM_ASSIGN_OR_RETURN(options.ordering, deform::OrderingFromName(args.ordering));
  DEFORM_ASSIGN_OR_RETURN(options.laplacian, deform::LaplacianWeightsFromName(args.laplacian));
  return options;
}

// The binding report: where the binding came from, per bone its vertices and rigid pieces, the
// warnings.
nlohmann::ordered_json BindingJson(const deform::BindingReport& report) {
  nlohmann::ordered_json out;
  out["source"] = report.source;
  out["seen_through_body"] = report.seen_through_body;
  out["reached_along_surface"] = report.reached_along_surface;
  out["straight_line"] = report.straight_line;
  out["bones"] = nlohmann::ordered_json::array();
  for (const deform::BoneBinding& bone : report.bones) {
    out["bones"].push_back({{"bone", bone.name},
                            {"vertices", bone.vertices},
                            {"rigid_vertices", bone.rigid_vertices},
                            {"rigid_pieces", bone.pieces},
                            {"anchors", bone.anchors}});
  }
  out["joints_outside"] = report.joints_outside;
  out["warnings"] = report.warnings;
  return out;
}

// The bone surfaces of the run: the input's own (the phantom's), capsules made by the sizing rule
// (MakeCapsuleBoneSurfaces), or none, and then every --bone-surface file.
StatusOr<std::vector<deform::BoneSurface>> BoneSurfacesFrom(const DeformArgs& args,
                                                            const deform::ModelInput& input) {
  std::vector<deform::BoneSurface> surfaces;
  if (args.bones == "input") {
    surfaces = input.bones;
  } else if (args.bones == "capsules") {
    surfaces = deform::MakeCapsuleBoneSurfaces(input.mesh, input.skeleton);
  } else if (args.bones != "none") {
    return Status::InvalidArgument("--bones must be input, capsules or none");
  }
  for (const std::string& spec : args.bone_surfaces) {
    DEFORM_ASSIGN_OR_RETURN(deform::BoneSurface surface,
                            deform::LoadBoneSurfaceSpec(spec, input.skeleton));
    surfaces.push_back(std::move(surface));
  }
  return surfaces;
}

nlohmann::ordered_json PenetrationJson(const deform::PenetrationSummary& summary) {
  return {{"vertices", summary.vertices}, {"max_depth", summary.max_depth}};
}

nlohmann::ordered_json DeformReport(const DeformArgs& args, const deform::ModelInput& input,
                                    const deform::DeformationModel& model, deform::Method method,
                                    const deform::MethodRun& run, int clamped) {
  const auto& q = run.quality;
  nlohmann::ordered_json out;
  out["mesh"] = input.description;
  out["input_warnings"] = input.warnings;
  out["method"] = deform::MethodName(method);
  if (args.animation.empty()) {
    out["pose"] = args.pose;
  } else {
    out["animation"] = args.animation;
    out["time"] = args.time;
  }
  out["vertices"] = input.mesh.num_vertices();
  out["triangles"] = input.mesh.num_triangles();
  out["joint_nodes"] = run.joint_nodes;
  // What the method ran with: laplacian is the model with neither, whatever the switches.
  const bool plain = method == deform::Method::kLaplacian;
  out["joint_nodes_enabled"] = !plain && model.options().use_joint_nodes;
  out["material_enabled"] = !plain && !model.options().uniform_material;
  out["anchors"] = run.anchors;
  out["binding"] = BindingJson(model.binding_report());
  const deform::LaplacianWeightReport& weights = model.laplacian_weight_report();
  out["laplacian"] = {{"weights", deform::LaplacianWeightsName(weights.kind)},
                      {"edges", weights.edges},
                      {"negative_edges", weights.negative_edges},
                      {"clamped_cotangents", weights.clamped_cotangents},
                      {"uniform_rows", weights.uniform_rows},
                      {"flips", weights.flips},
                      {"new_neighbor_pairs", weights.new_neighbor_pairs},
                      {"zeroed_edges", weights.zeroed_edges}};
  out["clamped_angles"] = clamped;
  out["volume_change"] = q.volume_change;
  out["clearance_min"] = q.clearance.min;
  out["clearance_p01"] = q.clearance.p01;
  out["sink_fraction"] = q.clearance.sink_fraction;
  out["rigid_zone_error"] = q.rigid_zone_error;
  out["max_displacement"] = q.max_displacement;
  out["bone_surfaces"] = args.bone_surface_count;
  if (args.bone_surface_count > 0) out["bone_penetration"] = PenetrationJson(q.bone_penetration);
  if (run.constraints.rounds > 0 || method == deform::Method::kPaper ||
      method == deform::Method::kPaperLinear) {
    const deform::ConstraintReport& c = run.constraints;
    out["constraints"] = {{"contacts", args.contacts},
                          {"volume", args.volume},
                          {"bone_reach", args.bone_reach},
                          {"reached_vertices", args.unanchored_vertices},
                          {"penetration_before", PenetrationJson(c.before)},
                          {"max_contacts", args.max_contacts},
                          {"scratch_bytes", args.constraint_scratch_bytes},
                          {"active_contacts", c.contacts},
                          {"rounds", c.rounds},
                          {"solves", c.solves},
                          {"backward_passes", c.backward_passes},
                          {"unit_solves", c.unit_solves},
                          {"unresolved", c.unresolved},
                          {"volume_change_before", c.volume_change_before},
                          {"ms", run.constraint_seconds * 1e3}};
  }
  out["inverted_triangles"] = q.inverted_triangles;
  out["self_intersections"] = q.self_intersections;
  out["precompute_ms"] = run.precompute_seconds * 1e3;
  out["factor_ms"] = run.factor_seconds * 1e3;
  out["factor_bytes"] = run.factor_bytes;
  if (method == deform::Method::kPaperLinear) out["response_bytes"] = run.response_bytes;
  out["solve_ms"] = run.solve_seconds * 1e3;
  out["frame_ms"] = run.frame_seconds * 1e3;
  out["repeat"] = args.repeat;
  return out;
}

// The dent the tools made: the vertices that moved more than 1e-3 of the diagonal from the
// tool-free frame, and the largest distance (in the tool-free frame, from the nearest tool's
// surface; 0 inside) at which one did.
nlohmann::ordered_json ToolDentJson(const deform::ToolSet& tools, const deform::Positions& free,
                                    const deform::Positions& posed, double diagonal) {
  constexpr double kDentFraction = 1e-3;
  int moved = 0;
  double extent = 0, largest = 0;
  for (Eigen::Index i = 0; i < free.rows(); ++i) {
    const double displacement = (posed.row(i) - free.row(i)).norm();
    largest = std::max(largest, displacement);
    if (displacement <= kDentFraction * diagonal) continue;
    ++moved;
    const Eigen::Vector3d x = free.row(i).transpose();
    double distance = std::numeric_limits<double>::infinity();
    for (int t = 0; t < tools.count; ++t) {
      const deform::Tool& tool = tools.tools[t];
      Eigen::Vector3d axis_point = tool.a;
      if (tool.shape == deform::Tool::Shape::kCapsule) {
        const Eigen::Vector3d segment = tool.b - tool.a;
        const double length2 = segment.squaredNorm();
        const double u =
            length2 > 0 ? std::clamp((x - tool.a).dot(segment) / length2, 0.0, 1.0) : 0;
        axis_point = tool.a + u * segment;
      }
      distance = std::min(distance, std::max(0.0, (x - axis_point).norm() - tool.radius));
    }
    extent = std::max(extent, distance);
  }
  return {{"threshold", kDentFraction * diagonal},
          {"vertices", moved},
          {"max_distance", extent},
          {"max_displacement", largest}};
}

int RunDeform(DeformArgs args) {
  auto method = deform::MethodFromName(args.method);
  if (!method.ok()) return Fail(method.status());
  auto options = ModelOptionsFrom(args);
  if (!options.ok()) return Fail(options.status());
  auto input = deform::LoadModelInput(args.mesh_path, args.skeleton_path, args.weights_path,
                                      args.phantom_vertices);
  if (!input.ok()) return Fail(input.status());
  deform::Pose pose;
  StatusOr<int> clamped = 0;
  if (args.animation.empty()) {
    auto terms = deform::ParsePoseSpec(args.pose, input->skeleton);
    if (!terms.ok()) return Fail(terms.status());
    clamped = deform::PoseFromTerms(input->skeleton, *terms, &pose);
    if (!clamped.ok()) return Fail(clamped.status());
  } else {
    // The glTF rig's own animation at that time (core/io/gltf_animation.h).
    if (!deform::IsGltfPath(args.mesh_path)) {
      return Fail(Status::InvalidArgument("--animation needs a glTF rig: --mesh RIG.glb"));
    }
    auto animations = deform::ReadGltfAnimationsFile(args.mesh_path, input->skeleton);
    if (!animations.ok()) return Fail(animations.status());
    auto index = deform::FindAnimation(*animations, args.animation);
    if (!index.ok()) return Fail(index.status().WithContext(args.mesh_path));
    auto sampled = deform::SamplePose(*animations, *index, args.time);
    if (!sampled.ok()) return Fail(sampled.status());
    pose = sampled->pose;
  }
  auto surfaces = BoneSurfacesFrom(args, *input);
  if (!surfaces.ok()) return Fail(surfaces.status());
  args.bone_surface_count = static_cast<int>(surfaces->size());
  deform::ConstraintOptions constraint_options;
  constraint_options.keep_volume = args.volume;
  constraint_options.bone_reach = args.bone_reach;
  if (!args.contacts) constraint_options.max_contacts = 0;
  const Status unanchored = deform::UnanchorReachedSkin(input->mesh, input->skeleton, *surfaces,
                                                        constraint_options, &*options);
  if (!unanchored.ok()) return Fail(unanchored);
  args.unanchored_vertices = static_cast<int>(options->unanchored_vertices.size());
  auto model =
      deform::DeformationModel::Build(input->mesh, input->skeleton, *options,
                                      input->weights.has_value() ? &*input->weights : nullptr);
  if (!model.ok()) return Fail(model.status());
  std::shared_ptr<const deform::BoneContacts> bones;
  if (!surfaces->empty()) {
    auto made = deform::BoneContacts::Create(*surfaces, input->skeleton, input->mesh,
                                             (*model)->rigid_bones());
    if (!made.ok()) return Fail(made.status());
    bones = *made;
  }
  auto constraints = deform::SkinConstraints::Create(**model, bones, constraint_options);
  if (!constraints.ok()) return Fail(constraints.status());
  args.max_contacts = (*constraints)->options().max_contacts;
  args.constraint_scratch_bytes = (*constraints)->ScratchBytes();
  deform::ToolSet tools;
  for (const std::string& spec : args.tools) {
    auto tool = deform::ParseToolSpec(spec);
    if (!tool.ok()) return Fail(tool.status());
    if (!tools.Add(*tool)) {
      return Fail(Status::InvalidArgument("at most " + std::to_string(deform::ToolSet::kMaxTools) +
                                          " --tool"));
    }
  }
  const Eigen::Vector3d lower = input->mesh.vertices.colwise().minCoeff().transpose();
  const Eigen::Vector3d upper = input->mesh.vertices.colwise().maxCoeff().transpose();
  if (const Status valid = deform::ValidateToolSet(tools, lower, upper); !valid.ok()) {
    return Fail(valid);
  }
  auto run = deform::RunMethod(**model, *method, pose, args.repeat, constraints->get(),
                               tools.empty() ? nullptr : &tools);
  if (!run.ok()) return Fail(run.status());
  if (!args.out_bones_dir.empty()) {
    std::vector<deform::RigidTransform> transforms;
    deform::ForwardKinematics(input->skeleton, pose, &transforms);
    const Status written =
        deform::WritePosedBoneSurfaces(*surfaces, input->skeleton, transforms, args.out_bones_dir);
    if (!written.ok()) return Fail(written);
  }
  if (!args.out_path.empty()) {
    const Status written =
        deform::WriteMeshFile({run->posed, input->mesh.triangles}, args.out_path);
    if (!written.ok()) return Fail(written);
  }
  for (const std::string& warning : input->warnings) {
    std::cerr << "deformctl: warning: " << warning << "\n";
  }
  for (const std::string& warning : (*model)->binding_report().warnings) {
    std::cerr << "deformctl: warning: " << warning << "\n";
  }
  nlohmann::ordered_json report = DeformReport(args, *input, **model, *method, *run, *clamped);
  if (!tools.empty()) {
    // The dent: against the same frame without tools.
    auto free = deform::RunMethod(**model, *method, pose, 1, constraints->get());
    if (!free.ok()) return Fail(free.status());
    report["tools"] = static_cast<int>(args.tools.size());
    report["tool_penetration_max"] = run->constraints.tool_after.max_depth;
    report["tool_penetration"] = {{"before", PenetrationJson(run->constraints.tool_before)},
                                  {"after", PenetrationJson(run->constraints.tool_after)},
                                  {"contacts", run->constraints.tool_contacts},
                                  {"unresolved", run->constraints.tools_unresolved}};
    report["tool_dent"] =
        ToolDentJson(tools, free->posed, run->posed, (*model)->bounding_box_diagonal());
  }
  std::cout << report.dump() << std::endl;
  return 0;
}

int RunPhantom(const PhantomArgs& args) {
  auto phantom = deform::MakeKneePhantom(args.vertices);
  if (!phantom.ok()) return Fail(phantom.status());
  const Status written = deform::WriteMeshFile(phantom->mesh, args.out_path);
  if (!written.ok()) return Fail(written);
  if (!args.skeleton_out_path.empty()) {
    std::ofstream out(args.skeleton_out_path);
    out << deform::SkeletonToJson(phantom->skeleton) << "\n";
    if (!out) return Fail(Status::InvalidArgument("cannot write '" + args.skeleton_out_path + "'"));
  }
  nlohmann::ordered_json out;
  out["mesh"] = args.out_path;
  out["skeleton"] = args.skeleton_out_path;
  out["vertices"] = phantom->mesh.num_vertices();
  out["triangles"] = phantom->mesh.num_triangles();
  std::cout << out.dump() << std::endl;
  return 0;
}

// "on" and "off" for a boolean option.
std::map<std::string, bool> OnOff() { return {{"on", true}, {"off", false}}; }

// An option whose default --help shows.
template <typename T>
CLI::Option* AddWithDefault(CLI::App* command, const std::string& name, T* value,
                            const std::string& description) {
  return command->add_option(name, *value, description)->capture_default_str();
}

CLI::App* AddDeformCommand(CLI::App* app, DeformArgs* args) {
  CLI::App* command =
      app->add_subcommand("deform", "Pose a mesh and print quality and timings as JSON");
  command->add_option("--mesh", args->mesh_path,
                      "Mesh file (.obj .ply .stl .off), or a skinned glTF rig (.gltf .glb) that "
                      "brings its own skeleton and weights; default: the built-in knee phantom");
  command->add_option("--skeleton", args->skeleton_path,
                      "Skeleton file (.tgf or JSON); required with --mesh, except a glTF rig");
  command->add_option("--weights", args->weights_path,
                      "Skinning weights (.dmat or .csv: one row per mesh vertex, one column per "
                      "skeleton bone) to bind with instead of binding through the body; the "
                      "baselines (lbs, dqs) use them too");
  AddWithDefault(command, "--phantom-vertices", &args->phantom_vertices,
                 "Resolution of the phantom");
  CLI::Option* pose = AddWithDefault(command, "--pose", &args->pose,
                                     "JOINT:AXIS:DEGREES[,...], e.g. knee:flexion:90 or 1:x:90");
  CLI::Option* animation =
      command
          ->add_option("--animation", args->animation,
                       "Pose a glTF rig (--mesh RIG.glb) as its own animation NAME (or index from "
                       "0) poses it at --time")
          ->excludes(pose);
  command->add_option("--time", args->time, "Seconds into --animation (clamped to its keys)")
      ->capture_default_str()
      ->check(CLI::Range(-1e9, 1e9))
      ->needs(animation);
  AddWithDefault(command, "--method", &args->method,
                 "paper | paper-linear (linear rotation blend, no per-frame solve) | laplacian | "
                 "lbs | dqs | cor (optimized centres of rotation) | ddm (direct delta mush)");
  command->add_option("--out", args->out_path,
                      "Write the deformed mesh (format from the extension)");
  AddWithDefault(command, "--repeat", &args->repeat,
                 "Frames to time; solve_ms (the triangular solve) and frame_ms (the whole frame) "
                 "are their medians")
      ->check(CLI::Range(1, 100000));
  AddWithDefault(command, "--radius-factor", &args->radius_factor,
                 "Joint region radius in limb radii");
  AddWithDefault(command, "--ordering", &args->ordering,
                 "Fill-reducing ordering: auto | metis | amd | natural");
  command->add_option("--bone-surface", args->bone_surfaces,
                      "A bone surface FILE:BONE (a closed mesh file, .obj .ply .stl .off, carried "
                      "by BONE: an index, HEAD-TAIL, or the joint it starts at); repeatable");
  AddWithDefault(command, "--bones", &args->bones,
                 "Bone surfaces besides --bone-surface: input (the phantom's femur, tibia and "
                 "patella) | capsules (one per bone, sized by the skin) | none");
  command
      ->add_option("--contacts", args->contacts,
                   "on | off: keep the skin outside the bone surfaces (paper, paper-linear)")
      ->transform(CLI::CheckedTransformer(OnOff()))
      ->default_str("on");
  command
      ->add_option("--bone-reach", args->bone_reach,
                   "on | off: leave the skin a bone surface reaches across a joint out of the "
                   "rigid zones, so that contacts may move it (with --contacts on)")
      ->transform(CLI::CheckedTransformer(OnOff()))
      ->default_str("on");
  command
      ->add_option("--volume", args->volume,
                   "on | off: keep the skin's enclosed volume (paper, paper-linear)")
      ->transform(CLI::CheckedTransformer(OnOff()))
      ->default_str("on");
  command->add_option("--tool", args->tools,
                      "A tool pressing the skin (paper, paper-linear), in model units and the "
                      "posed skin's frame: sphere:X,Y,Z,R or capsule:X0,Y0,Z0,X1,Y1,Z1,R; "
                      "repeatable, at most " +
                          std::to_string(deform::ToolSet::kMaxTools));
  command->add_option("--out-bones", args->out_bones_dir,
                      "Write each bone surface, posed, as DIR/NAME.obj");
  AddWithDefault(command, "--joint-nodes", &args->joint_nodes,
                 "Joint centre nodes (off: the paper's model without them, for ablation)")
      ->check(CLI::IsMember({"on", "off"}));
  AddWithDefault(command, "--material", &args->material,
                 "Material weights (off: every row weight 1, for ablation)")
      ->check(CLI::IsMember({"on", "off"}));
  command->add_option("--material-profile", args->material_profile,
                      "The default material profile RIGID,SOFT,SEAM (relative row weights far "
                      "from a joint, in its region, on the region's border)");
  AddWithDefault(command, "--laplacian", &args->laplacian,
                 "Laplacian edge weights: uniform | cotangent | intrinsic (intrinsic Delaunay "
                 "cotangent)");
  AddWithDefault(command, "--rigid-weight-tolerance", &args->rigid_weight_tolerance,
                 "With given weights (--weights, a glTF rig): a vertex whose largest weight is at "
                 "least 1 - this is rigid on that bone (rigid_weight_tolerance, in [0, 0.5))");
  return command;
}

CLI::App* AddPhantomCommand(CLI::App* app, PhantomArgs* args) {
  CLI::App* command =
      app->add_subcommand("phantom", "Write the built-in knee phantom and its skeleton");
  command->add_option("--out", args->out_path, "Mesh file to write")->required();
  command->add_option("--skeleton-out", args->skeleton_out_path, "Skeleton JSON file to write");
  AddWithDefault(command, "--vertices", &args->vertices, "Approximate vertex count");
  return command;
}

// --help and the like exit 0 through CLI11; a bad command line is one line on stderr, exit 2.
int ParseFailure(const CLI::App& app, const CLI::ParseError& error) {
  if (error.get_exit_code() == 0) return app.exit(error);
  std::cerr << "deformctl: " << error.what() << "\n";
  return 2;
}

}  // namespace

int main(int argc, char** argv) {
  spdlog::set_level(spdlog::level::warn);
  CLI::App app{
      "deformctl: joint-aware Laplacian deformation of a limb mesh, from the command line"};
  app.require_subcommand(1);
  DeformArgs deform_args;
  PhantomArgs phantom_args;
  const CLI::App* deform_command = AddDeformCommand(&app, &deform_args);
  AddPhantomCommand(&app, &phantom_args);
  app.set_version_flag("--version", deform::VersionLine("deformctl"));
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return ParseFailure(app, e);
  }
  return *deform_command ? RunDeform(deform_args) : RunPhantom(phantom_args);
}
