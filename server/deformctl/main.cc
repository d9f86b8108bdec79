// deformctl: the deformation core from the command line.
//
//   deformctl deform [--mesh FILE --skeleton FILE [--weights FILE] | --mesh RIG.glb]
//                    --pose SPEC [--method paper|paper-linear|laplacian|lbs|dqs]
//                    [--out FILE] [--repeat N]
//   deformctl phantom --out FILE [--skeleton-out FILE] [--vertices N]
//
// Prints one JSON object on stdout; errors are one line on stderr and a non-zero exit code.
#include <spdlog/spdlog.h>

#include <CLI/CLI.hpp>
#include <fstream>
#include <iostream>
#include <nlohmann/json.hpp>
#include <string>

#include "core/eval/method_comparison.h"
#include "core/io/mesh_io.h"
#include "core/io/model_input.h"
#include "core/io/phantom.h"
#include "core/io/skeleton_io.h"

namespace {

using deform::Status;

struct DeformArgs {
  std::string mesh_path;
  std::string skeleton_path;
  std::string weights_path;
  int phantom_vertices = deform::kDefaultPhantomVertices;
  std::string pose = "rest";
  std::string method = "paper";
  std::string out_path;
  int repeat = 1;
  double radius_factor = 1.5;
  std::string ordering = "auto";
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

int RunDeform(const DeformArgs& args) {
  auto method = deform::MethodFromName(args.method);
  if (!method.ok()) return Fail(method.status());
  auto input = deform::LoadModelInput(args.mesh_path, args.skeleton_path, args.weights_path,
                                      args.phantom_vertices);
  if (!input.ok()) return Fail(input.status());
  auto terms = deform::ParsePoseSpec(args.pose, input->skeleton);
  if (!terms.ok()) return Fail(terms.status());
  deform::Pose pose;
  auto clamped = deform::PoseFromTerms(input->skeleton, *terms, &pose);
  if (!clamped.ok()) return Fail(clamped.status());

  deform::ModelOptions options = deform::ModelOptions::Paper();
  options.regions.radius_factor = args.radius_factor;
  if (args.ordering == "metis") {
    options.ordering = deform::Ordering::kMetis;
  } else if (args.ordering == "amd") {
    options.ordering = deform::Ordering::kAmd;
  } else if (args.ordering == "natural") {
    options.ordering = deform::Ordering::kNatural;
  }
  auto model = deform::DeformationModel::Build(input->mesh, input->skeleton, options);
  if (!model.ok()) return Fail(model.status());
  auto run = deform::RunMethod(**model, *method, pose, args.repeat);
  if (!run.ok()) return Fail(run.status());

  if (!args.out_path.empty()) {
    deform::TriangleMesh posed{run->posed, input->mesh.triangles};
    const Status written = deform::WriteMeshFile(posed, args.out_path);
    if (!written.ok()) return Fail(written);
  }
  const auto& q = run->quality;
  nlohmann::ordered_json out;
  out["mesh"] = input->description;
  out["method"] = deform::MethodName(*method);
  out["pose"] = args.pose;
  out["vertices"] = input->mesh.num_vertices();
  out["triangles"] = input->mesh.num_triangles();
  if (input->weights.has_value()) {
    // Read and checked against the mesh and skeleton, not yet used: the model binds by geometry.
    out["skin_weights"] = args.weights_path.empty() ? "glTF" : args.weights_path;
    out["skin_weights_used"] = false;
  }
  out["joint_nodes"] = run->joint_nodes;
  out["anchors"] = run->anchors;
  out["clamped_angles"] = *clamped;
  out["volume_change"] = q.volume_change;
  out["clearance_min"] = q.clearance.min;
  out["clearance_p01"] = q.clearance.p01;
  out["sink_fraction"] = q.clearance.sink_fraction;
  out["rigid_zone_error"] = q.rigid_zone_error;
  out["max_displacement"] = q.max_displacement;
  out["precompute_ms"] = run->precompute_seconds * 1e3;
  out["factor_ms"] = run->factor_seconds * 1e3;
  out["factor_bytes"] = run->factor_bytes;
  if (*method == deform::Method::kPaperLinear) out["response_bytes"] = run->response_bytes;
  out["solve_ms"] = run->solve_seconds * 1e3;
  out["frame_ms"] = run->frame_seconds * 1e3;
  out["repeat"] = args.repeat;
  std::cout << out.dump() << std::endl;
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

}  // namespace

int main(int argc, char** argv) {
  spdlog::set_level(spdlog::level::warn);
  CLI::App app{
      "deformctl: joint-aware Laplacian deformation of a limb mesh, from the command line"};
  app.require_subcommand(1);

  DeformArgs deform_args;
  CLI::App* deform_cmd =
      app.add_subcommand("deform", "Pose a mesh and print quality and timings as JSON");
  deform_cmd->add_option("--mesh", deform_args.mesh_path,
                         "Mesh file (.obj .ply .stl .off), or a skinned glTF rig (.gltf .glb) that "
                         "brings its own skeleton and weights; default: the built-in knee phantom");
  deform_cmd->add_option("--skeleton", deform_args.skeleton_path,
                         "Skeleton file (.tgf or JSON); required with --mesh, except a glTF rig");
  deform_cmd->add_option(
      "--weights", deform_args.weights_path,
      "Skinning weights (.dmat or .csv: one row per mesh vertex, one column per "
      "skeleton bone), checked against the mesh and skeleton; used by the model "
      "once binding from weights lands (until then the model binds by geometry)");
  deform_cmd
      ->add_option("--phantom-vertices", deform_args.phantom_vertices, "Resolution of the phantom")
      ->capture_default_str();
  deform_cmd
      ->add_option("--pose", deform_args.pose,
                   "JOINT:AXIS:DEGREES[,...], e.g. knee:flexion:90 or 1:x:90")
      ->capture_default_str();
  deform_cmd
      ->add_option("--method", deform_args.method,
                   "paper | paper-linear (linear rotation blend, no per-frame solve) | laplacian | "
                   "lbs | dqs")
      ->capture_default_str();
  deform_cmd->add_option("--out", deform_args.out_path,
                         "Write the deformed mesh (format from the extension)");
  deform_cmd
      ->add_option("--repeat", deform_args.repeat,
                   "Frames to time; solve_ms (the triangular solve) and frame_ms (the whole frame) "
                   "are their medians")
      ->capture_default_str()
      ->check(CLI::Range(1, 100000));
  deform_cmd
      ->add_option("--radius-factor", deform_args.radius_factor,
                   "Joint region radius in limb radii")
      ->capture_default_str();
  deform_cmd
      ->add_option("--ordering", deform_args.ordering,
                   "Fill-reducing ordering: auto | metis | amd | natural")
      ->capture_default_str()
      ->check(CLI::IsMember({"auto", "metis", "amd", "natural"}));

  PhantomArgs phantom_args;
  CLI::App* phantom_cmd =
      app.add_subcommand("phantom", "Write the built-in knee phantom and its skeleton");
  phantom_cmd->add_option("--out", phantom_args.out_path, "Mesh file to write")->required();
  phantom_cmd->add_option("--skeleton-out", phantom_args.skeleton_out_path,
                          "Skeleton JSON file to write");
  phantom_cmd->add_option("--vertices", phantom_args.vertices, "Approximate vertex count")
      ->capture_default_str();

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    if (e.get_exit_code() == 0) return app.exit(e);
    std::cerr << "deformctl: " << e.what() << "\n";
    return 2;
  }
  if (*deform_cmd) return RunDeform(deform_args);
  return RunPhantom(phantom_args);
}
