#include "core/io/bone_surface_io.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "core/geometry/bone_surface.h"
#include "core/geometry/pose.h"
#include "core/io/skeleton_io.h"

namespace deform {
namespace {

// One tetrahedron on the first bone of a two-bone chain, at rest.
struct OneSurface {
  OneSurface() {
    skeleton = *ParseTgf("1 0 0 0\n2 0 -1 0\n3 0 -2 0\n#\n1 2 1 0 0\n2 3 1 0 0\n#\n");
    BoneSurface surface;
    surface.name = "femur/left";
    surface.bone = 0;
    surface.mesh.vertices.resize(4, 3);
    surface.mesh.vertices << 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1;
    surface.mesh.triangles.resize(4, 3);
    surface.mesh.triangles << 0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3;
    surfaces.push_back(surface);
    bones.resize(skeleton.num_bones());
  }
  Skeleton skeleton;
  std::vector<BoneSurface> surfaces;
  std::vector<RigidTransform> bones;
};

std::filesystem::path FreshDir(const std::string& name) {
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() /
      (name + "-" + std::to_string(::testing::UnitTest::GetInstance()->random_seed()));
  std::filesystem::remove_all(dir);
  return dir;
}

TEST(WritePosedBoneSurfaces, CreatesTheDirectoryAndNamesFilesSafely) {
  const OneSurface input;
  const std::filesystem::path root = FreshDir("bone-surface-io");
  const std::filesystem::path dir = root / "nested" / "bones";
  const Status written =
      WritePosedBoneSurfaces(input.surfaces, input.skeleton, input.bones, dir.string());
  ASSERT_TRUE(written.ok()) << written.ToString();
  EXPECT_TRUE(std::filesystem::is_regular_file(dir / "femur_left.obj"));
  std::filesystem::remove_all(root);
}

TEST(WritePosedBoneSurfaces, AFileInTheWayIsAClearError) {
  const OneSurface input;
  const std::filesystem::path root = FreshDir("bone-surface-io-file");
  std::filesystem::create_directories(root);
  std::ofstream(root / "taken") << "x";
  const Status written = WritePosedBoneSurfaces(input.surfaces, input.skeleton, input.bones,
                                                (root / "taken").string());
  EXPECT_EQ(written.code(), StatusCode::kFailedPrecondition);
  EXPECT_NE(written.message().find("taken"), std::string::npos) << written.ToString();
  std::filesystem::remove_all(root);
}

}  // namespace
}  // namespace deform
