// write_split_rig OUT.glb: writes the built-in knee phantom as a skinned glTF rig whose vertices
// are split at seams, as exporters split them at UV seams: every seventh triangle gets its own
// copy of its three corners (same position, same weights), so the file holds more vertices than
// the solve (deformd and ReadGltf weld them back) and vertices used only through copies drop out.
// The weights are the phantom's own harmonic binding. For the animation benchmark's glTF test.
#include <iostream>
#include <vector>

#include "core/base/build_info.h"
#include "core/io/gltf_writer.h"
#include "core/io/phantom.h"
#include "core/model/deformation_model.h"

int main(int argc, char** argv) {
  if (deform::PrintVersionIfAsked(argc, argv, "write_split_rig")) return 0;
  if (argc != 2) {
    std::cerr << "usage: write_split_rig OUT.glb\n";
    return 2;
  }
  auto phantom = deform::MakeKneePhantom();
  if (!phantom.ok()) return std::cerr << phantom.status().ToString() << "\n", 1;
  auto model = deform::DeformationModel::Build(phantom->mesh, phantom->skeleton,
                                               deform::ModelOptions::Paper());
  if (!model.ok()) return std::cerr << model.status().ToString() << "\n", 1;
  const deform::BoneWeights& harmonic = (*model)->bone_weights();

  deform::TriangleMesh split = phantom->mesh;
  deform::SkinWeights weights;
  weights.num_bones = phantom->skeleton.num_bones();
  const auto add_weights_of = [&](int v) {
    const auto first = harmonic.offsets[v], last = harmonic.offsets[v + 1];
    weights.AddVertex(
        std::vector<int>(harmonic.bones.begin() + first, harmonic.bones.begin() + last),
        std::vector<double>(harmonic.weights.begin() + first, harmonic.weights.begin() + last));
  };
  const int n = phantom->mesh.num_vertices();
  for (int v = 0; v < n; ++v) add_weights_of(v);
  std::vector<int> copies;
  for (Eigen::Index t = 0; t < split.triangles.rows(); t += 7) {
    for (int c = 0; c < 3; ++c) {
      copies.push_back(split.triangles(t, c));
      split.triangles(t, c) = n + static_cast<int>(copies.size()) - 1;
    }
  }
  split.vertices.conservativeResize(n + static_cast<Eigen::Index>(copies.size()), 3);
  for (std::size_t k = 0; k < copies.size(); ++k) {
    split.vertices.row(n + static_cast<Eigen::Index>(k)) = phantom->mesh.vertices.row(copies[k]);
    add_weights_of(copies[k]);
  }
  const deform::Status written = deform::WriteGltfFile(argv[1], split, phantom->skeleton, weights);
  if (!written.ok()) return std::cerr << written.ToString() << "\n", 1;
  std::cout << "wrote " << argv[1] << ": " << split.num_vertices() << " vertices, " << n
            << " after welding\n";
  return 0;
}
