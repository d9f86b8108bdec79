// libFuzzer target: the LoadMesh stream handler (service/load/load_mesh_reactor.h) end to end,
// through a scripted transport that checks the transport contract (scripted_stream_transport.h),
// with limits small enough that a load the fuzzer finds builds quickly (phantoms up to
// kMaxVertices, uploads up to kMaxUploadBytes).
//
// The input is a client's script, one step after another (fuzz_reader.h): a step's first byte is
// its kind (low 7 bits modulo kStepKinds) and whether it is answered before a pending write (high
// bit), then the step's fields:
//   0 a phantom header: vertices (a signed byte, or 0xff and a 32-bit count), without_bones, name;
//   1 an upload header: mesh format, mesh_size_bytes (a byte, or 0xff and 64 bits), skeleton
//     format and file, weights format and file, a bone surface, serialized method options;
//   2 a chunk: a 16-bit length and that many bytes;
//   3 a serialized LoadMeshRequest (a byte's length of bytes), skipped when it does not parse;
//   4 an empty LoadMeshRequest; 5 the half-close; 6 a cancel; 7 the next write fails.
// Files are a 16-bit length and their bytes. The script's end is the half-close. Every call must
// end with OnDone (within the stall limit); then, once the worker has run every task the call
// posted, nothing may be left reserved and, with every mesh the call loaded unloaded, nothing
// counted against the memory budget.
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "deform/v1/deform.pb.h"
#include "service/load/load_mesh_reactor.h"
#include "tests/fuzz/fuzz_reader.h"
#include "tests/fuzz/fuzz_service.h"
#include "tests/fuzz/scripted_stream_transport.h"

namespace deform::fuzz {
namespace {

using Step = ClientStep<v1::LoadMeshRequest>;
constexpr int kStepKinds = 8;
constexpr std::size_t kMaxVertices = 200;
constexpr std::size_t kMaxUploadBytes = 64 << 10;

service::ServiceContext& TheContext() {
  static service::ServiceContext* context = [] {
    service::ServiceLimits limits;
    limits.max_vertices = kMaxVertices;
    limits.max_upload_bytes = kMaxUploadBytes;
    limits.max_bone_surface_bytes = 16 << 10;
    limits.max_meshes = 4;
    return NewFuzzContext(limits).release();
  }();
  return *context;
}

std::string File(FuzzReader& in) {
  const std::size_t length = in.Byte() | static_cast<std::size_t>(in.Byte()) << 8;
  return in.Bytes(length);
}

void ReadPhantomHeader(FuzzReader& in, v1::LoadMeshHeader* header) {
  const std::uint8_t vertices = in.Byte();
  header->mutable_phantom()->set_vertices(vertices == 0xff ? static_cast<std::int32_t>(in.U32())
                                                           : static_cast<std::int8_t>(vertices));
  header->mutable_phantom()->set_without_bones(in.Byte() & 1);
  header->set_name(in.ShortString());
}

void ReadUploadHeader(FuzzReader& in, v1::LoadMeshHeader* header) {
  v1::UploadSource* upload = header->mutable_upload();
  upload->set_format(static_cast<v1::MeshFormat>(in.Byte() % 7));
  const std::uint8_t size = in.Byte();
  upload->set_mesh_size_bytes(size == 0xff ? in.U64() : size == 0xfe ? in.U32() : size);
  upload->set_skeleton_format(static_cast<v1::SkeletonFormat>(in.Byte() % 4));
  upload->set_skeleton(File(in));
  upload->set_weights_format(static_cast<v1::SkinWeightsFormat>(in.Byte() % 4));
  upload->set_weights(File(in));
  const std::uint8_t extras = in.Byte();
  if (extras & 1) {
    v1::BoneSurfaceUpload* bone = upload->add_bone_surfaces();
    bone->set_name(in.ShortString());
    bone->set_format(static_cast<v1::MeshFormat>(in.Byte() % 7));
    bone->set_mesh(File(in));
    bone->set_bone(in.ShortString());
    if (extras & 2) {
      bone->set_blend_bone(in.ShortString());
      bone->set_blend(in.Double());
    }
  }
  upload->set_skip_gltf_bone_nodes(extras & 4);
  if (extras & 8) (void)header->mutable_options()->ParseFromString(in.ShortString());
  header->set_name(in.ShortString());
}

std::vector<Step> ReadScript(FuzzReader& in) {
  std::vector<Step> script;
  while (!in.empty()) {
    const std::uint8_t head = in.Byte();
    Step step;
    step.before_writes = (head & 0x80) != 0;
    switch ((head & 0x7f) % kStepKinds) {
      case 0:
        ReadPhantomHeader(in, step.request.mutable_header());
        break;
      case 1:
        ReadUploadHeader(in, step.request.mutable_header());
        break;
      case 2:
        step.request.set_chunk(File(in));
        break;
      case 3:
        if (!step.request.ParseFromString(in.ShortString())) continue;
        break;
      case 4:
        break;
      case 5:
        step.kind = Step::Kind::kHalfClose;
        break;
      case 6:
        step.kind = Step::Kind::kCancel;
        break;
      default:
        step.kind = Step::Kind::kFailNextWrite;
        break;
    }
    script.push_back(std::move(step));
  }
  return script;
}

}  // namespace
}  // namespace deform::fuzz

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace deform;
  service::ServiceContext& context = fuzz::TheContext();
  fuzz::FuzzReader in(data, size);
  const std::vector<fuzz::Step> script = fuzz::ReadScript(in);

  fuzz::ScriptedTransport<v1::LoadMeshRequest, v1::LoadMeshResponse> transport;
  service::StreamHandler* handler =
      service::NewLoadMeshStream(&context, service::Identity::Implicit(), &transport);
  bool ready = false;
  const fuzz::CallRecord record =
      transport.Run(handler, script, [&ready](const v1::LoadMeshResponse& response) {
        if (response.stage() == v1::LoadMeshResponse::STAGE_READY) {
          if (response.mesh().mesh_id().empty()) fuzz::CheckFailed("READY without a mesh id");
          ready = true;
        }
      });
  fuzz::WaitForWorkers(context.pool());

  if (record.finished_ok && !ready) fuzz::CheckFailed("a load ended OK without READY");
  if (context.admission().loads_in_progress() != 0 ||
      context.admission().memory_bytes_reserved() != 0) {
    fuzz::CheckFailed("a finished load still holds its mesh slot or reserved memory");
  }
  for (const auto& entry : context.registry().List()) (void)context.registry().Unload(entry->id);
  if (context.admission().memory_bytes_used() != 0) {
    fuzz::CheckFailed("memory still counted after every mesh was unloaded");
  }
  return 0;
}
