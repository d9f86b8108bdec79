// The one split of a listen address, at its last colon: what every rule about an address (loopback
// or not, its port, its Host names) starts from.
#include "service/base/listen_address.h"

#include <gtest/gtest.h>

namespace deform::service {
namespace {

TEST(ListenAddressTest, SplitsAtTheLastColonKeepingAnIpv6LiteralsBrackets) {
  const ListenHostAndPort v4 = SplitListenAddress("127.0.0.1:50051");
  EXPECT_EQ(v4.host, "127.0.0.1");
  EXPECT_EQ(v4.port, "50051");
  EXPECT_TRUE(v4.has_port);
  const ListenHostAndPort v6 = SplitListenAddress("[::1]:0");
  EXPECT_EQ(v6.host, "[::1]");
  EXPECT_EQ(v6.port, "0");
  const ListenHostAndPort name = SplitListenAddress("localhost:");
  EXPECT_EQ(name.host, "localhost");
  EXPECT_EQ(name.port, "");
  EXPECT_TRUE(name.has_port);
  const ListenHostAndPort bare = SplitListenAddress("deformd.ward.example");
  EXPECT_EQ(bare.host, "deformd.ward.example");
  EXPECT_EQ(bare.port, "");
  EXPECT_FALSE(bare.has_port);
}

TEST(ListenPort, DecimalDigitsUpTo65535Only) {
  EXPECT_EQ(ListenPort(SplitListenAddress("127.0.0.1:50051")), 50051);
  EXPECT_EQ(ListenPort(SplitListenAddress("[::1]:0")), 0);
  EXPECT_EQ(ListenPort(SplitListenAddress("h:65535")), 65535);
  for (const char* bad :
       {"h:65536", "h:", "h", "h:+80", "h: 80", "h:80 ", "h:-1", "h:099999", "h:abc", "h:8o"}) {
    EXPECT_EQ(ListenPort(SplitListenAddress(bad)), -1) << bad;
  }
}

}  // namespace
}  // namespace deform::service
