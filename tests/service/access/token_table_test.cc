// The token file's parser and the authenticator over it, without a server: hashed tokens, comments
// and blank lines, refused lines, the bearer scheme, and a failed load that changes nothing.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "service/access/identity.h"
#include "tests/service/support/temp_dir.h"

namespace deform {
namespace {

using test_support::TempDir;

TEST(TokenTableTest, ParsesCommentsAndRefusesBadLines) {
  const std::string hash = service::Sha256Hex("secret");
  EXPECT_EQ(hash, "2bb80d537b1da3e38bd30361aa855686bde0eacd7162fef6a25fe97bf527a25b");
  auto table = service::TokenTable::Parse("# comment\n\n  " + hash + "\tward-1 operator\r\n");
  ASSERT_TRUE(table.ok()) << table.status().ToString();
  ASSERT_NE(table->Find(hash), nullptr);
  EXPECT_EQ(table->Find(hash)->tenant, "ward-1");
  EXPECT_EQ(table->Find(hash)->role, service::Role::kOperator);
  for (const std::string& bad : std::vector<std::string>{
           hash + " ward-1", hash + " ward-1 admin", "abc ward-1 tenant", hash + " ward/1 tenant",
           hash + " ward-1 tenant\n" + hash + " ward-2 tenant"}) {
    SCOPED_TRACE(bad);
    EXPECT_EQ(service::TokenTable::Parse(bad).status().code(), StatusCode::kInvalidArgument);
  }
  TempDir dir;
  service::Authenticator tokens;
  ASSERT_TRUE(
      tokens.LoadTokenFile(dir.Write("tokens", service::Sha256Hex("secret") + "  ward-1  tenant\n"))
          .ok());
  EXPECT_TRUE(tokens.uses_tokens());
  EXPECT_TRUE(tokens.Authenticate("Bearer secret").ok());
  EXPECT_TRUE(tokens.Authenticate("bearer secret").ok());  // the scheme is case-insensitive
  for (const char* refused :
       {"", "Bearer", "Bearer ", "Basic c2VjcmV0", "secret", "Bearer secret2", "Bearer SECRET"}) {
    SCOPED_TRACE(refused);
    EXPECT_EQ(tokens.Authenticate(refused).status().code(), StatusCode::kUnauthenticated);
  }
  EXPECT_EQ(tokens.LoadTokenFile("/nonexistent/tokens").code(), StatusCode::kNotFound);
  EXPECT_TRUE(tokens.Authenticate("Bearer secret").ok());  // a failed load changes nothing

  service::Authenticator none;
  EXPECT_FALSE(none.uses_tokens());
  EXPECT_EQ(none.Reload().code(), StatusCode::kFailedPrecondition);
  auto implicit = none.Authenticate("");
  ASSERT_TRUE(implicit.ok());
  EXPECT_EQ(implicit->tenant, service::Identity::Implicit().tenant);
}

}  // namespace
}  // namespace deform
