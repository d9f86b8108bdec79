#include "service/registry/mesh_registry.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "core/io/phantom.h"
#include "service/transport/status_mapping.h"

namespace deform::service {
namespace {

using ::testing::HasSubstr;

std::shared_ptr<const DeformationModel> SmallModel() {
  auto phantom = MakeKneePhantom(300);
  EXPECT_TRUE(phantom.ok());
  auto model = DeformationModel::Build(phantom->mesh, phantom->skeleton, ModelOptions::Paper());
  EXPECT_TRUE(model.ok()) << model.status().ToString();
  return *model;
}

TEST(MeshRegistryTest, RegistersFindsListsAndUnloads) {
  Admission admission(ServiceLimits{});
  MeshRegistry registry(&admission);
  const auto model = SmallModel();
  auto reservation = admission.ReserveMesh();
  ASSERT_TRUE(reservation.ok());
  auto first = registry.Register(std::move(*reservation), "first", model);
  ASSERT_TRUE(first.ok()) << first.status().ToString();
  auto second = registry.Register(admission.ReserveMesh().value(), "second", model);
  ASSERT_TRUE(second.ok());
  EXPECT_NE((*first)->id, (*second)->id);
  EXPECT_EQ((*first)->memory_bytes, model->EstimatedBytes());
  EXPECT_EQ(admission.memory_bytes_used(), 2 * model->EstimatedBytes());

  auto found = registry.Find((*first)->id);
  ASSERT_TRUE(found.ok());
  EXPECT_EQ((*found)->name, "first");
  ASSERT_EQ(registry.List().size(), 2u);
  EXPECT_EQ(registry.List()[0]->name, "first");

  ASSERT_TRUE(registry.Unload((*first)->id).ok());
  EXPECT_TRUE((*first)->unloaded.load());
  EXPECT_EQ(registry.Find((*first)->id).status().code(), StatusCode::kNotFound);
  EXPECT_EQ(registry.Unload((*first)->id).code(), StatusCode::kNotFound);
  EXPECT_EQ(registry.Find("nonsense").status().code(), StatusCode::kNotFound);
  EXPECT_EQ(registry.mesh_count(), 1);
  EXPECT_EQ(admission.memory_bytes_used(), model->EstimatedBytes());
}

TEST(MeshRegistryTest, AMeshsMemoryCountsItsFileOrderMaps) {
  Admission admission(ServiceLimits{});
  MeshRegistry registry(&admission);
  const auto model = SmallModel();
  MeshFileMetadata file_metadata;  // a glTF's: two more file vertices than the mesh, one unused
  for (int v = 0; v < model->mesh().num_vertices(); ++v) {
    file_metadata.file_vertex_to_mesh.push_back(v);
  }
  file_metadata.file_vertex_to_mesh.insert(file_metadata.file_vertex_to_mesh.end(), {0, 1});
  file_metadata.unused_file_vertices = {model->mesh().num_vertices() + 1};
  const std::size_t map_bytes = sizeof(int) * (model->mesh().num_vertices() + 3);
  auto entry = registry.Register(admission.ReserveMesh().value(), "rig", model, file_metadata);
  ASSERT_TRUE(entry.ok()) << entry.status().ToString();
  EXPECT_EQ((*entry)->memory_bytes, model->EstimatedBytes() + map_bytes);
  EXPECT_EQ(admission.memory_bytes_used(), model->EstimatedBytes() + map_bytes);
}

TEST(MeshRegistryTest, ReservationsCountAgainstTheMeshLimitUntilReleased) {
  ServiceLimits limits;
  limits.max_meshes = 2;
  Admission admission(limits);
  MeshRegistry registry(&admission);
  auto a = admission.ReserveMesh();
  auto b = admission.ReserveMesh();
  ASSERT_TRUE(a.ok() && b.ok());
  auto c = admission.ReserveMesh();
  ASSERT_FALSE(c.ok());
  EXPECT_EQ(c.status().code(), StatusCode::kResourceExhausted);
  EXPECT_THAT(c.status().message(), HasSubstr("mesh limit"));
  a->Release();
  EXPECT_TRUE(admission.ReserveMesh().ok());  // and released again at once
  {
    auto d = admission.ReserveMesh();
    ASSERT_TRUE(d.ok());
    EXPECT_FALSE(admission.ReserveMesh().ok());
  }
  EXPECT_TRUE(admission.ReserveMesh().ok());
}

TEST(MeshRegistryTest, MemoryBudgetRefusesAModelThatDoesNotFit) {
  const auto model = SmallModel();
  ServiceLimits limits;
  limits.max_memory_bytes = model->EstimatedBytes() + model->EstimatedBytes() / 2;
  limits.max_meshes = 2;
  Admission admission(limits);
  MeshRegistry registry(&admission);
  ASSERT_TRUE(registry.Register(admission.ReserveMesh().value(), "fits", model).ok());
  auto refused = registry.Register(admission.ReserveMesh().value(), "too much", model);
  ASSERT_FALSE(refused.ok());
  EXPECT_EQ(refused.status().code(), StatusCode::kResourceExhausted);
  EXPECT_THAT(refused.status().message(), HasSubstr("memory budget"));
  EXPECT_EQ(registry.mesh_count(), 1);
  // The refused load's slot was released: one mesh loaded, one slot free.
  auto slot = admission.ReserveMesh();
  EXPECT_TRUE(slot.ok());
  EXPECT_FALSE(admission.ReserveMesh().ok());
}

TEST(MeshRegistryTest, LoadsInProgressHoldTheirMemoryUntilRegisteredOrReleased) {
  const auto model = SmallModel();
  ServiceLimits limits;
  limits.max_memory_bytes = std::size_t{10} << 20;
  limits.tenant_max_memory_bytes = std::size_t{8} << 20;
  Admission admission(limits);
  MeshRegistry registry(&admission);
  auto first = admission.ReserveMesh("a").value();
  auto second = admission.ReserveMesh("b").value();
  ASSERT_TRUE(admission.ReserveMemory(&first, std::size_t{6} << 20, "the first").ok());
  // The last of the budget cannot be taken twice.
  const Status refused = admission.ReserveMemory(&second, std::size_t{6} << 20, "the second");
  EXPECT_EQ(refused.code(), StatusCode::kResourceExhausted);
  EXPECT_THAT(refused.message(), HasSubstr("the second needs about 6 MiB, 6 MiB of the 10 MiB"));
  EXPECT_EQ(second.memory_bytes(), 0u);
  // A reservation may shrink or grow within what is left; the tenant's budget counts it too.
  ASSERT_TRUE(admission.ReserveMemory(&first, std::size_t{1} << 20, "the first").ok());
  EXPECT_EQ(admission.memory_bytes_reserved(), std::size_t{1} << 20);
  const Status tenant = admission.ReserveMemory(&second, std::size_t{9} << 20, "the second");
  EXPECT_THAT(tenant.message(), HasSubstr("tenant memory budget"));
  ASSERT_TRUE(admission.ReserveMemory(&second, std::size_t{6} << 20, "the second").ok());
  EXPECT_EQ(admission.loads_in_progress(), 2);
  // Registering swaps the reservation's memory for the model's; releasing frees it.
  ASSERT_TRUE(registry.Register(std::move(first), "first", model).ok());
  EXPECT_EQ(admission.memory_bytes_reserved(), std::size_t{6} << 20);
  EXPECT_EQ(admission.memory_bytes_used(), model->EstimatedBytes());
  second.Release();
  EXPECT_EQ(admission.memory_bytes_reserved(), 0u);
  EXPECT_EQ(admission.loads_in_progress(), 0);
}

TEST(StatusMappingTest, KeepsCodeAndMessage) {
  EXPECT_TRUE(ToGrpcStatus(Status::Ok()).ok());
  const grpc::Status status = ToGrpcStatus(Status::ResourceExhausted("too big"));
  EXPECT_EQ(status.error_code(), grpc::StatusCode::RESOURCE_EXHAUSTED);
  EXPECT_EQ(status.error_message(), "too big");
  EXPECT_EQ(ToGrpcCode(StatusCode::kInvalidArgument), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_EQ(ToGrpcCode(StatusCode::kNotFound), grpc::StatusCode::NOT_FOUND);
  EXPECT_EQ(ToGrpcCode(StatusCode::kOutOfRange), grpc::StatusCode::OUT_OF_RANGE);
  EXPECT_EQ(ToGrpcCode(StatusCode::kFailedPrecondition), grpc::StatusCode::FAILED_PRECONDITION);
  EXPECT_EQ(ToGrpcCode(StatusCode::kInternal), grpc::StatusCode::INTERNAL);
}

}  // namespace
}  // namespace deform::service
