// The static root serves files under it and nothing else (web/static_files.h), and the WebSocket
// token is read from the upgrade the way web_auth.h states.
#include "service/rpc/static_files.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>

#include "service/transport/web_auth.h"

namespace deform::web {
namespace {

namespace fs = std::filesystem;

class StaticFilesTest : public ::testing::Test {
 protected:
  void SetUp() override {
    base_ = fs::temp_directory_path() / ("deform_static_" + std::to_string(::getpid()));
    fs::remove_all(base_);
    fs::create_directories(base_ / "root" / "vendor");
    std::ofstream(base_ / "root" / "index.html") << "page";
    std::ofstream(base_ / "root" / "vendor" / "three.module.js") << "lib";
    std::ofstream(base_ / "secret.txt") << "outside";
    fs::create_symlink(base_ / "secret.txt", base_ / "root" / "link.txt");
    root_ = base_ / "root";
  }
  void TearDown() override { fs::remove_all(base_); }

  fs::path base_;
  fs::path root_;
};

TEST_F(StaticFilesTest, ServesFilesUnderTheRoot) {
  EXPECT_EQ(ResolveStaticPath(root_, "/"), fs::canonical(root_ / "index.html"));
  EXPECT_EQ(ResolveStaticPath(root_, "/index.html?v=2"), fs::canonical(root_ / "index.html"));
  EXPECT_EQ(ResolveStaticPath(root_, "/vendor/three.module.js"),
            fs::canonical(root_ / "vendor" / "three.module.js"));
  EXPECT_EQ(ResolveStaticPath(root_, "/vendor/three%2emodule.js"),
            fs::canonical(root_ / "vendor" / "three.module.js"));
}

TEST_F(StaticFilesTest, RefusesEverythingOutsideTheRoot) {
  for (const char* target :
       {"/../secret.txt", "/vendor/../../secret.txt", "/%2e%2e/secret.txt", "/..%2fsecret.txt",
        "/vendor/%2E%2E/%2E%2E/secret.txt", "/link.txt", "/..\\secret.txt", "//secret.txt",
        "/./index.html", "/index.html%00.js", "/%zz", "/%2", "index.html", "", "/missing.html",
        "/vendor"}) {
    EXPECT_FALSE(ResolveStaticPath(root_, target).has_value()) << target;
  }
}

TEST(ContentTypeTest, ByExtension) {
  EXPECT_EQ(ContentTypeFor("a/viewer.js"), "text/javascript; charset=utf-8");
  EXPECT_EQ(ContentTypeFor("index.html"), "text/html; charset=utf-8");
  EXPECT_EQ(ContentTypeFor("blob.bin"), "application/octet-stream");
}

TEST(WebAuthTest, TokenFromTheSubprotocolOrTheHeader) {
  // "secret" in base64url is "c2VjcmV0".
  EXPECT_EQ(AuthorizationFromUpgrade("", "deform.v1, bearer.c2VjcmV0"), "Bearer secret");
  EXPECT_EQ(AuthorizationFromUpgrade("", "bearer.c2VjcmV0=="), "Bearer secret");
  EXPECT_EQ(AuthorizationFromUpgrade("Bearer other", "bearer.c2VjcmV0"), "Bearer other");
  EXPECT_EQ(AuthorizationFromUpgrade("", "deform.v1"), "");
  EXPECT_EQ(AuthorizationFromUpgrade("", "bearer.!!"), "Bearer ");
  EXPECT_TRUE(OffersDeformSubprotocol("bearer.x, deform.v1"));
  EXPECT_FALSE(OffersDeformSubprotocol("deform.v2"));
}

}  // namespace
}  // namespace deform::web
