// libFuzzer target: a LoadMesh header as the server checks it before reserving anything. The
// bytes are a serialized deform.v1.LoadMeshHeader; CheckLoadHeader (string limits, source, sizes
// without overflow) and ModelOptionsFromProto (against the knee phantom's skeleton) must give a
// Status, never a crash or a sanitizer report.
#include <cstddef>
#include <cstdint>

#include "deform/v1/deform.pb.h"
#include "service/load/load_header.h"
#include "service/messages/proto_conversion.h"
#include "tests/fuzz/fuzz_model.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const deform::DeformationModel& model = deform::fuzz::PhantomModel();
  deform::v1::LoadMeshHeader header;
  if (!header.ParseFromArray(data, static_cast<int>(size))) return 0;
  deform::service::ServiceLimits limits;
  limits.max_upload_bytes = std::size_t{256} << 20;
  (void)deform::service::CheckLoadHeader(header, limits);
  (void)deform::service::ModelOptionsFromProto(header.options(), model.skeleton());
  return 0;
}
