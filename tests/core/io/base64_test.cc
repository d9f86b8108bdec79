// Base64Encode against RFC 4648's test vectors (section 10), and bytes above 0x7f.
#include "core/io/base64.h"

#include <gtest/gtest.h>

#include <cstddef>
#include <string>

namespace deform {
namespace {

TEST(Base64Encode, MatchesTheRfcVectors) {
  // The encodings of "foobar"'s prefixes, the empty one first.
  const char* const kEncoded[] = {"", "Zg==", "Zm8=", "Zm9v", "Zm9vYg==", "Zm9vYmE=", "Zm9vYmFy"};
  for (std::size_t n = 0; n <= 6; ++n) {
    EXPECT_EQ(Base64Encode(std::string("foobar", n)), kEncoded[n]) << n << " bytes";
  }
}

TEST(Base64Encode, ReadsBytesAsUnsigned) {
  EXPECT_EQ(Base64Encode(std::string("\xff\xfe\x00", 3)), "//4A");
  EXPECT_EQ(Base64Encode(std::string("\x80", 1)), "gA==");
}

}  // namespace
}  // namespace deform
