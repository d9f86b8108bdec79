// Content keys (mesh_key.h): what names a mesh, and what does not.
#include "service/registry/mesh_key.h"

#include <gtest/gtest.h>

#include <regex>
#include <string>

#include "service/registry/mesh_id.h"

namespace deform {
namespace {

v1::LoadMeshHeader Upload(const std::string& name) {
  v1::LoadMeshHeader header;
  header.set_name(name);
  header.mutable_upload()->set_format(v1::MESH_FORMAT_OBJ);
  header.mutable_upload()->set_skeleton("joints");
  header.mutable_options()->set_rotation_blend(v1::ROTATION_BLEND_LINEAR);
  return header;
}

TEST(MeshKeyTest, TheSameContentHasTheSameKeyWhateverItsName) {
  const service::MeshKeys keys(std::string(32, 'k'));
  const std::string key = keys.KeyOf("ward-a", Upload("bed 7"), "v 0 0 0\n");
  EXPECT_TRUE(std::regex_match(key, std::regex("mesh-[0-9a-f]{32}"))) << key;
  EXPECT_TRUE(service::LooksLikeMeshId(key));
  EXPECT_EQ(keys.KeyOf("ward-a", Upload("another label"), "v 0 0 0\n"), key);
  // Replicas sharing the secret agree.
  EXPECT_EQ(service::MeshKeys(std::string(32, 'k')).KeyOf("ward-a", Upload("x"), "v 0 0 0\n"), key);
}

TEST(MeshKeyTest, EverythingThatMakesTheModelChangesTheKey) {
  const service::MeshKeys keys(std::string(32, 'k'));
  const std::string key = keys.KeyOf("ward-a", Upload(""), "v 0 0 0\n");
  EXPECT_NE(keys.KeyOf("ward-b", Upload(""), "v 0 0 0\n"), key);  // the tenant
  EXPECT_NE(keys.KeyOf("ward-a", Upload(""), "v 0 0 1\n"), key);  // the mesh bytes
  v1::LoadMeshHeader options = Upload("");
  options.mutable_options()->set_rotation_blend(v1::ROTATION_BLEND_QUATERNION);
  EXPECT_NE(keys.KeyOf("ward-a", options, "v 0 0 0\n"), key);  // the method options
  v1::LoadMeshHeader skeleton = Upload("");
  skeleton.mutable_upload()->set_skeleton("joints2");
  EXPECT_NE(keys.KeyOf("ward-a", skeleton, "v 0 0 0\n"), key);  // the skeleton
  // Parts are length-prefixed: moving bytes between tenant and mesh does not collide.
  EXPECT_NE(keys.KeyOf("ward-a", Upload(""), "v"), keys.KeyOf("ward-av", Upload(""), ""));
}

TEST(MeshKeyTest, WithoutTheSecretTheKeyCannotBeComputed) {
  const std::string key =
      service::MeshKeys(std::string(32, 'k')).KeyOf("ward-a", Upload(""), "v 0 0 0\n");
  EXPECT_NE(service::MeshKeys(std::string(32, 'j')).KeyOf("ward-a", Upload(""), "v 0 0 0\n"), key);
  // Two random secrets (two servers without --store-key) disagree.
  EXPECT_NE(service::MeshKeys().KeyOf("ward-a", Upload(""), "v"),
            service::MeshKeys().KeyOf("ward-a", Upload(""), "v"));
}

}  // namespace
}  // namespace deform
