#include "core/io/skeleton_io.h"

#include <cctype>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <limits>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "core/base/text.h"
#include "internal/file_bytes.h"

namespace deform {
namespace {

constexpr char kGltfIsARig[] =
    "is a glTF rig, not a skeleton file: read it whole (mesh, skeleton and weights) as a glTF";

// `bytes` without a UTF-8 byte order mark and leading white space.
std::string_view ContentStart(std::string_view bytes) {
  if (bytes.substr(0, 3) == "\xEF\xBB\xBF") bytes.remove_prefix(3);
  while (!bytes.empty() && (bytes.front() == ' ' || bytes.front() == '\t' ||
                            bytes.front() == '\n' || bytes.front() == '\r')) {
    bytes.remove_prefix(1);
  }
  return bytes;
}

// INVALID_ARGUMENT naming content in a format that is no skeleton file (BVH, a binary glTF).
Status RefuseForeignContent(std::string_view bytes) {
  const std::string_view start = ContentStart(bytes);
  if (start.substr(0, 9) == "HIERARCHY") return Status::InvalidArgument(kBvhNotSupported);
  if (bytes.substr(0, 4) == "glTF") {
    return Status::InvalidArgument(std::string("the data (binary glTF) ") + kGltfIsARig);
  }
  return Status::Ok();
}

std::string Shown(std::string_view text) {
  std::string shown(text.substr(0, 16));
  for (char& c : shown) {
    if (c < 0x20 || c > 0x7e) c = '?';
  }
  return "'" + shown + (text.size() > 16 ? "...'" : "'");
}

}  // namespace

StatusOr<SkeletonFormat> SkeletonFormatFromBytes(std::string_view bytes) {
  DEFORM_RETURN_IF_ERROR(RefuseForeignContent(bytes));
  const std::string_view start = ContentStart(bytes);
  if (start.empty()) return Status::InvalidArgument("the skeleton data is empty");
  if (start.front() == '{') return SkeletonFormat::kJson;
  const char c = start.front();
  if ((c >= '0' && c <= '9') || c == '+' || c == '-' || c == '#') return SkeletonFormat::kTgf;
  return Status::InvalidArgument("unknown skeleton format: the data starts with " + Shown(start) +
                                 " (expected TGF, the project's JSON, or a skinned glTF read as "
                                 "a rig)");
}

namespace {

// A TGF joint line's fields after the line's start: "index x y z [extra...]".
StatusOr<Joint> TgfJoint(std::istringstream* fields, const std::string& where, std::size_t index) {
  std::string label;
  double x, y, z;
  if (!(*fields >> label >> x >> y >> z)) {
    return Status::InvalidArgument(where + ": expected 'index x y z'");
  }
  Joint joint;
  joint.rest_position = {x, y, z};
  if (!joint.rest_position.allFinite()) {
    return Status::InvalidArgument(where + ": non-finite joint position");
  }
  joint.name = "joint" + std::to_string(index);
  return joint;
}

// A TGF bone line: "a b [flags...]", 1-based joints, as 0-based (head, tail).
StatusOr<std::pair<int, int>> TgfBone(std::istringstream* fields, const std::string& where,
                                      std::size_t num_joints) {
  long long a, b;
  if (!(*fields >> a >> b)) return Status::InvalidArgument(where + ": expected 'a b'");
  const long long last = static_cast<long long>(num_joints);
  if (a < 1 || b < 1 || a > last || b > last) {
    return Status::InvalidArgument(where + ": bone joint index out of range 1.." +
                                   std::to_string(num_joints));
  }
  return std::make_pair(static_cast<int>(a - 1), static_cast<int>(b - 1));
}

}  // namespace

StatusOr<Skeleton> ParseTgf(std::string_view text) {
  DEFORM_RETURN_IF_ERROR(RefuseForeignContent(text));
  std::istringstream in{std::string(text)};
  std::string line;
  std::vector<Joint> joints;
  std::vector<std::pair<int, int>> bones;
  int section = 0;  // 0 joints, 1 bones, 2 done
  for (int line_number = 1; std::getline(in, line) && section < 2; ++line_number) {
    const std::string_view content = Trim(line);
    if (content.empty()) continue;
    if (content.front() == '#') {
      ++section;
      continue;
    }
    std::istringstream fields(line);
    const std::string where = "TGF line " + std::to_string(line_number);
    if (section == 0) {
      DEFORM_ASSIGN_OR_RETURN(Joint joint, TgfJoint(&fields, where, joints.size()));
      joints.push_back(std::move(joint));
    } else {
      DEFORM_ASSIGN_OR_RETURN(const auto bone, TgfBone(&fields, where, joints.size()));
      bones.push_back(bone);
    }
  }
  if (section == 0) return Status::InvalidArgument("TGF has no '#' line after the joints");
  return Skeleton::Create(std::move(joints), std::move(bones));
}

namespace {

StatusOr<Eigen::Vector3d> JsonVector(const nlohmann::json& value, const std::string& what) {
  if (!value.is_array() || value.size() != 3) {
    return Status::InvalidArgument(what + " must be an array of 3 numbers");
  }
  Eigen::Vector3d v;
  for (int c = 0; c < 3; ++c) {
    if (!value[c].is_number()) return Status::InvalidArgument(what + " must hold numbers");
    v[c] = value[c].get<double>();
  }
  return v;
}

StatusOr<int> JsonJointReference(const nlohmann::json& value, const std::vector<Joint>& joints) {
  if (value.is_number_integer()) {
    const long long j = value.get<long long>();
    if (j >= 0 && j < static_cast<long long>(joints.size())) return static_cast<int>(j);
  } else if (value.is_string()) {
    const std::string name = value.get<std::string>();
    for (size_t j = 0; j < joints.size(); ++j) {
      if (joints[j].name == name) return static_cast<int>(j);
    }
  }
  return Status::InvalidArgument("bone references unknown joint " + value.dump());
}

// INVALID_ARGUMENT naming the first key of `object` (described by `what`) outside `known`.
Status RefuseUnknownKeys(const nlohmann::json& object, const std::string& what,
                         std::initializer_list<const char*> known) {
  for (const auto& item : object.items()) {
    bool found = false;
    for (const char* key : known) found = found || item.key() == key;
    if (found) continue;
    std::string list;
    for (const char* key : known) list += (list.empty() ? "" : ", ") + std::string(key);
    return Status::InvalidArgument(what + " has key '" + item.key() +
                                   "', which is not part of the skeleton JSON format (" + what +
                                   " keys: " + list + ")");
  }
  return Status::Ok();
}

// Whether `value` is an object with a string "name" and every key of `required`.
bool IsNamedObject(const nlohmann::json& value, std::initializer_list<const char*> required) {
  if (!value.is_object() || !value.contains("name") || !value["name"].is_string()) return false;
  for (const char* key : required) {
    if (!value.contains(key)) return false;
  }
  return true;
}

// dof[key] into *degrees when present; INVALID_ARGUMENT when it is not a number.
Status ReadOptionalDegrees(const nlohmann::json& dof, const char* key, const std::string& where,
                           double* degrees) {
  if (!dof.contains(key)) return Status::Ok();
  if (!dof[key].is_number()) {
    return Status::InvalidArgument(where + ": dof '" + key + "' not a number");
  }
  *degrees = dof[key].get<double>();
  return Status::Ok();
}

StatusOr<DegreeOfFreedom> DegreeOfFreedomFromJson(const nlohmann::json& value,
                                                  const std::string& where) {
  if (!IsNamedObject(value, {"axis"})) {
    return Status::InvalidArgument(where + ": each dof needs 'name' and 'axis'");
  }
  DEFORM_RETURN_IF_ERROR(RefuseUnknownKeys(value, where + " dof", {"name", "axis", "min", "max"}));
  DegreeOfFreedom dof;
  dof.name = value["name"].get<std::string>();
  DEFORM_ASSIGN_OR_RETURN(dof.axis, JsonVector(value["axis"], where + " dof axis"));
  DEFORM_RETURN_IF_ERROR(ReadOptionalDegrees(value, "min", where, &dof.min_degrees));
  DEFORM_RETURN_IF_ERROR(ReadOptionalDegrees(value, "max", where, &dof.max_degrees));
  return dof;
}

// Joint `index` of the document.
StatusOr<Joint> JointFromJson(const nlohmann::json& value, std::size_t index) {
  const std::string where = "joint " + std::to_string(index);
  if (!IsNamedObject(value, {"position"})) {
    return Status::InvalidArgument(where + " needs 'name' (string) and 'position'");
  }
  DEFORM_RETURN_IF_ERROR(RefuseUnknownKeys(value, where, {"name", "position", "dofs"}));
  Joint joint;
  joint.name = value["name"].get<std::string>();
  DEFORM_ASSIGN_OR_RETURN(joint.rest_position, JsonVector(value["position"], where + " position"));
  if (!value.contains("dofs")) return joint;
  if (!value["dofs"].is_array()) return Status::InvalidArgument(where + " 'dofs' must be an array");
  for (const auto& d : value["dofs"]) {
    DEFORM_ASSIGN_OR_RETURN(DegreeOfFreedom dof, DegreeOfFreedomFromJson(d, where));
    joint.dofs.push_back(std::move(dof));
  }
  return joint;
}

StatusOr<Skeleton> ParseSkeletonJsonValue(const nlohmann::json& doc) {
  if (doc.is_object() && doc.contains("asset") &&
      (doc.contains("nodes") || doc.contains("skins") || doc.contains("meshes"))) {
    return Status::InvalidArgument(std::string("the JSON ") + kGltfIsARig);
  }
  if (doc.is_object()) {
    DEFORM_RETURN_IF_ERROR(RefuseUnknownKeys(doc, "the skeleton", {"joints", "bones"}));
  }
  if (!doc.is_object() || !doc.contains("joints") || !doc["joints"].is_array() ||
      !doc.contains("bones") || !doc["bones"].is_array()) {
    return Status::InvalidArgument("skeleton JSON needs arrays 'joints' and 'bones'");
  }
  std::vector<Joint> joints;
  for (const auto& j : doc["joints"]) {
    DEFORM_ASSIGN_OR_RETURN(Joint joint, JointFromJson(j, joints.size()));
    joints.push_back(std::move(joint));
  }
  std::vector<std::pair<int, int>> bones;
  std::vector<int> parents;
  for (const auto& b : doc["bones"]) {
    const std::string where = "bone " + std::to_string(bones.size());
    int parent = -1;
    nlohmann::json head_value, tail_value;
    if (b.is_array() && b.size() == 2) {
      head_value = b[0];
      tail_value = b[1];
    } else if (b.is_object() && b.contains("head") && b.contains("tail")) {
      DEFORM_RETURN_IF_ERROR(RefuseUnknownKeys(b, where, {"head", "tail", "parent"}));
      head_value = b["head"];
      tail_value = b["tail"];
      if (b.contains("parent") && !b["parent"].is_null()) {
        if (!b["parent"].is_number_integer()) {
          return Status::InvalidArgument(where + " 'parent' must be a 0-based bone index");
        }
        const auto value = b["parent"].get<long long>();
        if (value < -1 || value > std::numeric_limits<int>::max()) {
          return Status::InvalidArgument(where + " 'parent' " + std::to_string(value) +
                                         " is not a bone index");
        }
        parent = static_cast<int>(value);
      }
    } else {
      return Status::InvalidArgument(
          "each bone must be [head, tail] or {\"head\": ..., \"tail\": ..., \"parent\": ...}");
    }
    DEFORM_ASSIGN_OR_RETURN(const int head, JsonJointReference(head_value, joints));
    DEFORM_ASSIGN_OR_RETURN(const int tail, JsonJointReference(tail_value, joints));
    bones.emplace_back(head, tail);
    parents.push_back(parent);
  }
  return Skeleton::Create(std::move(joints), std::move(bones), parents);
}

}  // namespace

StatusOr<Skeleton> ParseSkeletonJson(std::string_view text) {
  DEFORM_RETURN_IF_ERROR(RefuseForeignContent(text));
  nlohmann::json doc = nlohmann::json::parse(text.begin(), text.end(), nullptr,
                                             /*allow_exceptions=*/false);
  if (doc.is_discarded()) return Status::InvalidArgument("skeleton JSON does not parse");
  return ParseSkeletonJsonValue(doc);
}

std::string SkeletonToJson(const Skeleton& skeleton) {
  nlohmann::json doc;
  doc["joints"] = nlohmann::json::array();
  for (const Joint& j : skeleton.joints()) {
    nlohmann::json joint;
    joint["name"] = j.name;
    joint["position"] = {j.rest_position.x(), j.rest_position.y(), j.rest_position.z()};
    joint["dofs"] = nlohmann::json::array();
    for (const DegreeOfFreedom& d : j.dofs) {
      joint["dofs"].push_back({{"name", d.name},
                               {"axis", {d.axis.x(), d.axis.y(), d.axis.z()}},
                               {"min", d.min_degrees},
                               {"max", d.max_degrees}});
    }
    doc["joints"].push_back(joint);
  }
  doc["bones"] = nlohmann::json::array();
  for (int k = 0; k < skeleton.num_bones(); ++k) {
    const Bone& b = skeleton.bone(k);
    if (skeleton.HasExplicitParent(k)) {
      doc["bones"].push_back({{"head", skeleton.joint(b.head_joint).name},
                              {"tail", skeleton.joint(b.tail_joint).name},
                              {"parent", b.parent_bone}});
    } else {
      doc["bones"].push_back(
          {skeleton.joint(b.head_joint).name, skeleton.joint(b.tail_joint).name});
    }
  }
  return doc.dump(2);
}

StatusOr<Skeleton> ParseSkeleton(std::string_view bytes, SkeletonFormat format) {
  return format == SkeletonFormat::kTgf ? ParseTgf(bytes) : ParseSkeletonJson(bytes);
}

StatusOr<Skeleton> ReadSkeletonFile(const std::string& path) {
  DEFORM_ASSIGN_OR_RETURN(const std::string bytes,
                          io_internal::ReadFileBytes(path, "skeleton file"));
  std::string extension = std::filesystem::path(path).extension().string();
  for (char& c : extension) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  StatusOr<SkeletonFormat> format = SkeletonFormat::kTgf;
  if (extension == ".json") {
    format = SkeletonFormat::kJson;
  } else if (extension != ".tgf") {
    format = SkeletonFormatFromBytes(bytes);
  }
  StatusOr<Skeleton> skeleton =
      format.ok() ? ParseSkeleton(bytes, *format) : StatusOr<Skeleton>(format.status());
  if (!skeleton.ok()) return skeleton.status().WithContext(path);
  return skeleton;
}

}  // namespace deform
