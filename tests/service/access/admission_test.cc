#include "service/access/admission.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

namespace deform::service {
namespace {

using ::testing::HasSubstr;

TEST(AdmissionTest, StreamsCountPerTenantAndInAllUntilReleased) {
  ServiceLimits limits;
  limits.max_streams = 3;
  limits.tenant_max_streams = 2;
  Admission admission(limits);
  ASSERT_TRUE(admission.AcquireStream("a").ok());
  ASSERT_TRUE(admission.AcquireStream("a").ok());
  const Status tenant = admission.AcquireStream("a");
  EXPECT_EQ(tenant.code(), StatusCode::kResourceExhausted);
  EXPECT_THAT(tenant.message(), HasSubstr("--tenant-max-streams"));
  ASSERT_TRUE(admission.AcquireStream("b").ok());
  const Status server = admission.AcquireStream("c");
  EXPECT_EQ(server.code(), StatusCode::kResourceExhausted);
  EXPECT_THAT(server.message(), HasSubstr("--max-streams"));
  admission.ReleaseStream("a");
  EXPECT_TRUE(admission.AcquireStream("c").ok());
  // A release of a stream never acquired changes nothing.
  admission.ReleaseStream("nobody");
  EXPECT_FALSE(admission.AcquireStream("d").ok());
}

TEST(AdmissionTest, NoStreamLimitWhenZero) {
  ServiceLimits limits;
  limits.max_streams = 0;
  Admission admission(limits);
  for (int i = 0; i < 1000; ++i) ASSERT_TRUE(admission.AcquireStream("a").ok());
}

TEST(AdmissionTest, AnUnloadedMeshKeepsItsMemoryWhileInUse) {
  ServiceLimits limits;
  limits.max_memory_bytes = std::size_t{10} << 20;
  limits.max_meshes = 1;
  Admission admission(limits);
  auto slot = admission.ReserveMesh("a");
  ASSERT_TRUE(slot.ok());
  ASSERT_TRUE(admission.AdmitMesh(std::move(*slot), std::size_t{6} << 20).ok());
  EXPECT_EQ(admission.loads_in_progress(), 0);
  EXPECT_FALSE(admission.ReserveMesh("a").ok());  // the one slot is the loaded mesh's
  admission.MeshUnloaded("a", std::size_t{6} << 20, /*still_in_use=*/true);
  EXPECT_EQ(admission.memory_bytes_used(), std::size_t{6} << 20);
  auto next = admission.ReserveMesh("a");  // the slot is free again, the memory is not
  ASSERT_TRUE(next.ok());
  EXPECT_EQ(admission.ReserveMemory(&*next, std::size_t{6} << 20, "the next").code(),
            StatusCode::kResourceExhausted);
  admission.ReleaseUnloadedMesh("a", std::size_t{6} << 20);
  EXPECT_EQ(admission.memory_bytes_used(), 0u);
  EXPECT_TRUE(admission.ReserveMemory(&*next, std::size_t{6} << 20, "the next").ok());
}

TEST(AdmissionTest, AStreamsHoldCountsInTheBudget) {
  ServiceLimits limits;
  limits.max_memory_bytes = std::size_t{4} << 20;
  Admission admission(limits);
  Admission::MemoryHold hold = admission.HoldMemory("a");
  ASSERT_TRUE(hold.Resize(std::size_t{3} << 20, "the stream").ok());
  EXPECT_EQ(admission.memory_bytes_streams(), std::size_t{3} << 20);
  const Status refused = hold.Resize(std::size_t{5} << 20, "the stream");
  EXPECT_THAT(refused.message(), HasSubstr("memory budget exceeded"));
  EXPECT_EQ(hold.bytes(), std::size_t{3} << 20);
  {
    Admission::MemoryHold moved = std::move(hold);
    EXPECT_EQ(admission.memory_bytes_streams(), std::size_t{3} << 20);
  }
  EXPECT_EQ(admission.memory_bytes_streams(), 0u);
}

}  // namespace
}  // namespace deform::service
