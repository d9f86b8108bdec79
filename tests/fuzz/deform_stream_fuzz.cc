// libFuzzer target: the Deform stream handler (service/deform/deform_stream_reactor.h) end to end,
// through a scripted transport that checks the transport contract (scripted_stream_transport.h),
// against a context holding two loaded knee phantoms (one with its bones, so with contacts and
// tools; one without).
//
// The input is a client's script, one step after another (fuzz_reader.h): a step's first byte is
// its kind (low 7 bits modulo kStepKinds) and whether it is answered before a pending write (high
// bit), then the step's fields:
//   0 start: mesh (0 the phantom with bones, 1 the one without, 2 a string, 3 the first's id with
//     a byte appended), encoding (a signed byte), max_error (a double);
//   1, 2 pose: sequence, timestamp, angles, rotations, root, tools (pose fields below);
//   3 stiffness: joint materials, region weights, vertex indices and weights;
//   4 a serialized DeformRequest (a byte's length of bytes), skipped when it does not parse;
//   5 a pose with bytes appended to its serialization (unknown or clashing fields);
//   6 an empty DeformRequest; 7 the half-close; 8 a cancel; 9 the next write fails.
// The script's end is the half-close. Every call must end with OnDone (within the stall limit);
// then, once the worker has run every task the call posted, the stream must have let go of the
// meshes, its stream slot and its memory, and it may have ended OK only after a half-close without
// a cancel or a failed write before its finish.
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "deform/v1/deform.pb.h"
#include "service/deform/deform_stream_reactor.h"
#include "tests/fuzz/fuzz_reader.h"
#include "tests/fuzz/fuzz_service.h"
#include "tests/fuzz/scripted_stream_transport.h"

namespace deform::fuzz {
namespace {

using Step = ClientStep<v1::DeformRequest>;
constexpr int kStepKinds = 10;

struct Fixture {
  std::unique_ptr<service::ServiceContext> context;
  std::shared_ptr<const service::MeshEntry> with_bones;
  std::shared_ptr<const service::MeshEntry> without_bones;
  long with_bones_references = 0;  // use_count with no stream open
  long without_bones_references = 0;
  std::vector<std::string> joint_names;
  std::vector<std::string> axis_names;
};

const Fixture& TheFixture() {
  static const Fixture* fixture = [] {
    auto* made = new Fixture;
    made->context = NewFuzzContext(service::ServiceLimits{});
    made->with_bones = LoadPhantom(made->context.get(), 200, /*without_bones=*/false);
    made->without_bones = LoadPhantom(made->context.get(), 200, /*without_bones=*/true);
    WaitForWorkers(made->context->pool());
    made->with_bones_references = made->with_bones.use_count();
    made->without_bones_references = made->without_bones.use_count();
    for (const Joint& joint : made->with_bones->model->skeleton().joints()) {
      made->joint_names.push_back(joint.name);
      for (const DegreeOfFreedom& dof : joint.dofs) made->axis_names.push_back(dof.name);
    }
    for (const char* axis : {"x", "y", "z"}) made->axis_names.push_back(axis);
    return made;
  }();
  return *fixture;
}

std::string JointName(FuzzReader& in, const Fixture& fixture) {
  const std::uint8_t choice = in.Byte();
  if (choice < 0xc0) return fixture.joint_names[choice % fixture.joint_names.size()];
  if (choice < 0xe0) return std::to_string(choice - 0xc0);  // an index, some beyond the joints
  if (choice < 0xf0) return "";
  return in.ShortString();
}

std::string AxisName(FuzzReader& in, const Fixture& fixture) {
  const std::uint8_t choice = in.Byte();
  if (choice < 0xf0) return fixture.axis_names[choice % fixture.axis_names.size()];
  return in.ShortString();
}

void ReadVector(FuzzReader& in, v1::Vector3* vector) {
  vector->set_x(in.Double());
  vector->set_y(in.Double());
  vector->set_z(in.Double());
}

void ReadPose(FuzzReader& in, const Fixture& fixture, v1::PoseUpdate* pose) {
  pose->set_sequence(in.Byte());
  pose->set_client_timestamp_ns(static_cast<std::int8_t>(in.Byte()));
  for (int i = in.Byte() % 5; i > 0; --i) {
    v1::JointAngle* angle = pose->add_angles();
    angle->set_joint(JointName(in, fixture));
    angle->set_axis(AxisName(in, fixture));
    angle->set_degrees(in.Double());
  }
  for (int i = in.Byte() % 3; i > 0; --i) {
    v1::JointRotation* rotation = pose->add_rotations();
    rotation->set_joint(JointName(in, fixture));
    rotation->set_w(in.Double());
    rotation->set_x(in.Double());
    rotation->set_y(in.Double());
    rotation->set_z(in.Double());
  }
  const std::uint8_t root = in.Byte();
  if (root & 1) ReadVector(in, pose->mutable_root()->mutable_translation());
  if (root & 2) {
    v1::Quaternion* q = pose->mutable_root()->mutable_rotation();
    q->set_w(in.Double());
    q->set_x(in.Double());
    q->set_y(in.Double());
    q->set_z(in.Double());
  }
  for (int i = in.Byte() % 6; i > 0; --i) {  // up to one beyond ToolSet::kMaxTools
    v1::ToolState* tool = pose->add_tools();
    const std::uint8_t shape = in.Byte();
    tool->set_shape(static_cast<v1::ToolState::Shape>(static_cast<std::int8_t>(shape & 0x7f) % 4));
    if (!(shape & 0x80)) ReadVector(in, tool->mutable_center());
    if (tool->shape() == v1::ToolState::SHAPE_CAPSULE) ReadVector(in, tool->mutable_end());
    tool->set_radius(in.Double());
  }
}

void ReadStiffness(FuzzReader& in, const Fixture& fixture, v1::StiffnessUpdate* stiffness) {
  for (int i = in.Byte() % 3; i > 0; --i) {
    v1::JointMaterialUpdate* update = stiffness->add_joint_materials();
    update->set_joint(JointName(in, fixture));
    const std::uint8_t set = in.Byte();
    if (set & 1) update->mutable_material()->set_rigid(in.Double());
    if (set & 2) update->mutable_material()->set_soft(in.Double());
    if (set & 4) update->mutable_material()->set_seam(in.Double());
  }
  for (int i = in.Byte() % 3; i > 0; --i) {
    v1::RegionWeight* weight = stiffness->add_region_weights();
    weight->set_joint(JointName(in, fixture));
    weight->set_weight(in.Double());
  }
  for (int i = in.Byte() % 4; i > 0; --i) {
    const std::uint8_t index = in.Byte();
    stiffness->add_vertex_indices(index == 0xff ? in.U32() : index);
  }
  for (int i = in.Byte() % 4; i > 0; --i) stiffness->add_vertex_weights(in.Double());
}

void ReadStart(FuzzReader& in, const Fixture& fixture, v1::DeformStart* start) {
  switch (in.Byte() % 4) {
    case 0:
      start->set_mesh_id(fixture.with_bones->id);
      break;
    case 1:
      start->set_mesh_id(fixture.without_bones->id);
      break;
    case 2:
      start->set_mesh_id(in.ShortString());
      break;
    default:
      start->set_mesh_id(fixture.with_bones->id + static_cast<char>(in.Byte()));
      break;
  }
  start->set_encoding(static_cast<v1::FrameEncoding>(static_cast<std::int8_t>(in.Byte())));
  start->set_max_error(in.Double());
}

std::vector<Step> ReadScript(FuzzReader& in, const Fixture& fixture) {
  std::vector<Step> script;
  while (!in.empty()) {
    const std::uint8_t head = in.Byte();
    Step step;
    step.before_writes = (head & 0x80) != 0;
    switch ((head & 0x7f) % kStepKinds) {
      case 0:
        ReadStart(in, fixture, step.request.mutable_start());
        break;
      case 1:
      case 2:
        ReadPose(in, fixture, step.request.mutable_pose());
        break;
      case 3:
        ReadStiffness(in, fixture, step.request.mutable_stiffness());
        break;
      case 4:
        if (!step.request.ParseFromString(in.ShortString())) continue;
        break;
      case 5: {
        ReadPose(in, fixture, step.request.mutable_pose());
        const std::string bytes = step.request.SerializeAsString() + in.ShortString();
        if (!step.request.ParseFromString(bytes)) continue;
        break;
      }
      case 6:
        break;
      case 7:
        step.kind = Step::Kind::kHalfClose;
        break;
      case 8:
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
  const fuzz::Fixture& fixture = fuzz::TheFixture();
  fuzz::FuzzReader in(data, size);
  const std::vector<fuzz::Step> script = fuzz::ReadScript(in, fixture);

  service::ServiceContext* context = fixture.context.get();
  fuzz::ScriptedTransport<v1::DeformRequest, v1::DeformResponse> transport;
  service::StreamHandler* handler =
      service::NewDeformStream(context, service::Identity::Implicit(), &transport);
  const fuzz::CallRecord record = transport.Run(handler, script, [](const v1::DeformResponse&) {});
  fuzz::WaitForWorkers(context->pool());

  if (fixture.with_bones.use_count() != fixture.with_bones_references ||
      fixture.without_bones.use_count() != fixture.without_bones_references) {
    fuzz::CheckFailed("a finished stream still holds its mesh");
  }
  if (context->streams().count() != 0 || context->admission().memory_bytes_streams() != 0) {
    fuzz::CheckFailed("a finished stream still holds its stream slot or memory");
  }
  if (record.finished_ok && (!record.half_closed || record.cancelled || record.write_failed)) {
    fuzz::CheckFailed("a stream ended OK without a half-close, or after a cancel or failure");
  }
  return 0;
}
