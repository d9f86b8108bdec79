// libFuzzer target: a Deform stream's stiffness update as the server converts it. The bytes are a
// serialized deform.v1.StiffnessUpdate; StiffnessFromProto checks it against the knee phantom's
// model (joints, regions, vertex indices, weights). An accepted update is refactorized when small
// enough to keep the run fast; rejections are Statuses.
#include <cstddef>
#include <cstdint>

#include "deform/v1/deform.pb.h"
#include "service/messages/proto_conversion.h"
#include "tests/fuzz/fuzz_model.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const deform::DeformationModel& model = deform::fuzz::PhantomModel();
  deform::v1::StiffnessUpdate update;
  if (!update.ParseFromArray(data, static_cast<int>(size))) return 0;
  auto stiffness = deform::service::StiffnessFromProto(update, model);
  if (stiffness.ok() && size < 64) (void)model.Factorize(*stiffness);
  return 0;
}
