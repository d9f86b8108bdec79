// Reading PLY data: the checks that come before OpenMesh's PLY reader, and the read.
//
// OpenMesh's PLY reader loops forever on a header without "end_header" or with an unparsable
// element count (it stops only on a stream error, and keeps appending elements); crashes on a
// "property" line before any "element"; loops over declared counts while the input has run out;
// reads list properties outside the face's vertex_indices/texcoord as single values
// (desynchronizing the rest); skips face properties declared before vertex_indices; and leaves a
// value unread when a known property (colour, normal, ...) has a type it cannot convert. It
// supports list counts of uchar/uint8/uint16/int only, and finds the binary body by assuming
// exactly one newline around "end_header". So the header is parsed here, checked against what
// the reader handles, the body walked, and OpenMesh is given a canonical header (one property
// per line, no comments, list counts renamed to the supported type of the same size, elements
// after the face element dropped since the reader never reads them) followed by the body.
#include <algorithm>
#include <cstdint>
#include <initializer_list>
#include <limits>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "mesh_io_internal.h"
#include "mesh_soup_importer.h"

namespace deform::mesh_io_internal {
namespace {

enum class PlyType { kInt8, kUint8, kInt16, kUint16, kInt32, kUint32, kFloat32, kFloat64 };

std::optional<PlyType> PlyTypeFromName(std::string_view name) {
  static const std::pair<std::string_view, PlyType> kNames[] = {
      {"char", PlyType::kInt8},      {"int8", PlyType::kInt8},       {"uchar", PlyType::kUint8},
      {"uint8", PlyType::kUint8},    {"short", PlyType::kInt16},     {"int16", PlyType::kInt16},
      {"ushort", PlyType::kUint16},  {"uint16", PlyType::kUint16},   {"int", PlyType::kInt32},
      {"int32", PlyType::kInt32},    {"uint", PlyType::kUint32},     {"uint32", PlyType::kUint32},
      {"float", PlyType::kFloat32},  {"float32", PlyType::kFloat32}, {"double", PlyType::kFloat64},
      {"float64", PlyType::kFloat64}};
  for (const auto& [type_name, type] : kNames) {
    if (name == type_name) return type;
  }
  return std::nullopt;
}

std::size_t PlyTypeSize(PlyType type) {
  switch (type) {
    case PlyType::kInt8:
    case PlyType::kUint8:
      return 1;
    case PlyType::kInt16:
    case PlyType::kUint16:
      return 2;
    case PlyType::kInt32:
    case PlyType::kUint32:
    case PlyType::kFloat32:
      return 4;
    case PlyType::kFloat64:
      return 8;
  }
  return 1;
}

bool IsPlyInteger(PlyType type) { return type != PlyType::kFloat32 && type != PlyType::kFloat64; }
bool IsPlySigned(PlyType type) {
  return type == PlyType::kInt8 || type == PlyType::kInt16 || type == PlyType::kInt32;
}

struct PlyProperty {
  std::string name;
  std::string type_name;  // a scalar's type, or a list's entry type, as written
  PlyType type = PlyType::kFloat32;
  std::optional<PlyType> count_type;  // set for a list
  bool is_list() const { return count_type.has_value(); }
};

struct PlyElement {
  std::string name;
  std::uint64_t count = 0;
  std::vector<PlyProperty> properties;
};

enum class PlyEncoding { kAscii, kBinaryLittleEndian, kBinaryBigEndian };

struct PlyHeader {
  PlyEncoding encoding = PlyEncoding::kAscii;
  std::vector<PlyElement> elements;
  std::size_t body_offset = 0;
};

bool IsVertexIndexList(const PlyElement& element, const PlyProperty& property) {
  return element.name == "face" && property.is_list() &&
         (property.name == "vertex_indices" || property.name == "vertex_index");
}

class PlyHeaderParser {
 public:
  explicit PlyHeaderParser(std::string_view bytes) : lines_(bytes) {}
  StatusOr<PlyHeader> Run();

 private:
  Status ParseFormat();
  Status ParseElement();
  Status ParseProperty();
  Status LineError(const std::string& message) const {
    return Status::InvalidArgument("PLY header line " + std::to_string(lines_.line_number()) +
                                   ": " + message);
  }

  LineReader lines_;
  std::vector<std::string_view> tokens_;
  PlyHeader header_;
  bool has_format_ = false;
};

StatusOr<PlyHeader> PlyHeaderParser::Run() {
  std::string_view line;
  lines_.Next(&line);
  if (Trim(line) != "ply" && Trim(line) != "PLY") {
    return Status::InvalidArgument("not PLY data: the first line is not 'ply'");
  }
  while (lines_.Next(&line)) {
    SplitTokens(line, &tokens_);
    if (tokens_.empty() || tokens_[0] == "comment" || tokens_[0] == "obj_info") continue;
    if (tokens_[0] == "end_header") {
      if (tokens_.size() != 1) return LineError("'end_header' must stand alone on its line");
      if (!has_format_) return Status::InvalidArgument("the PLY header has no 'format' line");
      header_.body_offset = lines_.position();
      return std::move(header_);
    }
    if (tokens_[0] == "format") {
      DEFORM_RETURN_IF_ERROR(ParseFormat());
    } else if (tokens_[0] == "element") {
      DEFORM_RETURN_IF_ERROR(ParseElement());
    } else if (tokens_[0] == "property") {
      DEFORM_RETURN_IF_ERROR(ParseProperty());
    } else {
      return LineError("unknown keyword " + Quoted(tokens_[0]));
    }
  }
  return Status::InvalidArgument("the PLY header has no 'end_header' line");
}

Status PlyHeaderParser::ParseFormat() {
  if (tokens_.size() != 3) return LineError("expected 'format <encoding> 1.0'");
  if (tokens_[1] == "ascii") {
    header_.encoding = PlyEncoding::kAscii;
  } else if (tokens_[1] == "binary_little_endian") {
    header_.encoding = PlyEncoding::kBinaryLittleEndian;
  } else if (tokens_[1] == "binary_big_endian") {
    header_.encoding = PlyEncoding::kBinaryBigEndian;
  } else {
    return LineError("unknown PLY encoding " + Quoted(tokens_[1]));
  }
  has_format_ = true;
  return Status::Ok();
}

Status PlyHeaderParser::ParseElement() {
  long long count = 0;
  if (tokens_.size() != 3 || !ParseInteger(tokens_[2], &count) || count < 0) {
    return LineError("expected 'element <name> <count>' with a non-negative count");
  }
  PlyElement element;
  element.name = std::string(tokens_[1]);
  element.count = static_cast<std::uint64_t>(count);
  header_.elements.push_back(std::move(element));
  return Status::Ok();
}

Status PlyHeaderParser::ParseProperty() {
  if (header_.elements.empty()) return LineError("a property comes before any element");
  const bool is_list = tokens_.size() >= 2 && tokens_[1] == "list";
  if (tokens_.size() != (is_list ? 5u : 3u)) {
    return LineError("expected 'property <type> <name>' or 'property list <type> <type> <name>'");
  }
  PlyProperty property;
  property.name = std::string(tokens_.back());
  property.type_name = std::string(tokens_[tokens_.size() - 2]);
  const std::optional<PlyType> type = PlyTypeFromName(property.type_name);
  if (!type) return LineError("unknown type " + Quoted(property.type_name));
  property.type = *type;
  if (is_list) {
    property.count_type = PlyTypeFromName(tokens_[2]);
    if (!property.count_type || !IsPlyInteger(*property.count_type)) {
      return LineError("a list count needs an integer type, not " + Quoted(tokens_[2]));
    }
  }
  std::vector<PlyProperty>& properties = header_.elements.back().properties;
  for (const PlyProperty& existing : properties) {
    if (existing.name == property.name) {
      return LineError("property " + Quoted(property.name) + " is declared twice");
    }
  }
  properties.push_back(std::move(property));
  return Status::Ok();
}

bool IsOneOf(std::string_view name, std::initializer_list<std::string_view> names) {
  return std::find(names.begin(), names.end(), name) != names.end();
}

Status UnsupportedPlyProperty(const PlyElement& element, const PlyProperty& property,
                              const std::string& why) {
  return Status::InvalidArgument("PLY " + element.name + " property " + Quoted(property.name) +
                                 " is not supported: " + why);
}

Status CheckPlyVertexElement(const PlyElement& vertex) {
  for (std::string_view axis : {"x", "y", "z"}) {
    const auto found = std::find_if(vertex.properties.begin(), vertex.properties.end(),
                                    [axis](const PlyProperty& p) { return p.name == axis; });
    if (found == vertex.properties.end()) {
      return Status::InvalidArgument("the PLY vertex element has no " + Quoted(axis) + " property");
    }
  }
  for (const PlyProperty& property : vertex.properties) {
    if (property.is_list()) return UnsupportedPlyProperty(vertex, property, "it is a list");
    if (IsOneOf(property.name, {"x", "y", "z", "nx", "ny", "nz", "u", "v", "s", "t"}) &&
        IsPlyInteger(property.type)) {
      return UnsupportedPlyProperty(vertex, property, "it must be float or double");
    }
    if (IsOneOf(property.name, {"red", "green", "blue", "alpha", "diffuse_red", "diffuse_green",
                                "diffuse_blue"}) &&
        property.type == PlyType::kFloat64) {
      return UnsupportedPlyProperty(vertex, property, "a colour cannot be double");
    }
  }
  return Status::Ok();
}

Status CheckPlyFaceElement(const PlyElement& face) {
  if (face.properties.empty() || !IsVertexIndexList(face, face.properties.front())) {
    return Status::InvalidArgument(
        "the PLY face element must start with a 'vertex_indices' list property");
  }
  if (!IsPlyInteger(face.properties.front().type)) {
    return UnsupportedPlyProperty(face, face.properties.front(), "indices must be integers");
  }
  for (std::size_t i = 1; i < face.properties.size(); ++i) {
    const PlyProperty& property = face.properties[i];
    if (property.is_list() && property.name != "texcoord") {
      return UnsupportedPlyProperty(face, property, "it is a list");
    }
    if (IsOneOf(property.name, {"red", "green", "blue", "alpha"}) &&
        property.type == PlyType::kFloat64) {
      return UnsupportedPlyProperty(face, property, "a colour cannot be double");
    }
    if (property.name == "texnumber" && !IsPlyInteger(property.type)) {
      return UnsupportedPlyProperty(face, property, "it must be an integer");
    }
  }
  return Status::Ok();
}

Status CheckPlyOtherElement(const PlyElement& element) {
  for (const PlyProperty& property : element.properties) {
    if (property.is_list()) return UnsupportedPlyProperty(element, property, "it is a list");
  }
  if (element.properties.empty() && element.count > 0) {
    return Status::InvalidArgument("the PLY element " + Quoted(element.name) +
                                   " has no properties");
  }
  return Status::Ok();
}

std::optional<std::size_t> FindPlyElement(const PlyHeader& header, std::string_view name) {
  for (std::size_t i = 0; i < header.elements.size(); ++i) {
    if (header.elements[i].name == name) return i;
  }
  return std::nullopt;
}

// Checks the header against the reader's abilities and `limits`, and drops the elements after
// the face element (which the reader never reads).
Status CheckPlyLayout(const MeshLimits& limits, PlyHeader* header) {
  for (std::size_t i = 0; i < header->elements.size(); ++i) {
    for (std::size_t j = 0; j < i; ++j) {
      if (header->elements[i].name == header->elements[j].name) {
        return Status::InvalidArgument("the PLY element " + Quoted(header->elements[i].name) +
                                       " is declared twice");
      }
    }
  }
  const std::optional<std::size_t> vertex = FindPlyElement(*header, "vertex");
  const std::optional<std::size_t> face = FindPlyElement(*header, "face");
  if (!vertex) return Status::InvalidArgument("the PLY data has no vertex element");
  if (face && *face < *vertex) {
    return Status::InvalidArgument("the PLY face element must come after the vertex element");
  }
  if (header->elements[*vertex].count > limits.max_vertices) {
    return DeclaresTooMany("the PLY header", header->elements[*vertex].count, "vertices",
                           limits.max_vertices);
  }
  if (face && header->elements[*face].count > limits.max_triangles) {
    return DeclaresTooMany("the PLY header", header->elements[*face].count, "faces",
                           limits.max_triangles);
  }
  if (face) header->elements.resize(*face + 1);
  for (std::size_t i = 0; i < header->elements.size(); ++i) {
    const PlyElement& element = header->elements[i];
    // The reader keeps counts in an unsigned int.
    if (element.count > std::numeric_limits<unsigned int>::max()) {
      return Status::InvalidArgument("the PLY element " + Quoted(element.name) +
                                     " has too many records");
    }
    if (i == vertex) {
      DEFORM_RETURN_IF_ERROR(CheckPlyVertexElement(element));
    } else if (i == face) {
      if (element.count > 0) DEFORM_RETURN_IF_ERROR(CheckPlyFaceElement(element));
    } else {
      DEFORM_RETURN_IF_ERROR(CheckPlyOtherElement(element));
    }
  }
  return Status::Ok();
}

// The list count type OpenMesh supports with the same size (counts are checked non-negative).
const char* CanonicalPlyCountType(PlyType type) {
  switch (PlyTypeSize(type)) {
    case 1:
      return "uchar";
    case 2:
      return "uint16";
    default:
      return "int";
  }
}

std::string CanonicalPlyHeader(const PlyHeader& header) {
  std::string text = "ply\nformat ";
  switch (header.encoding) {
    case PlyEncoding::kAscii:
      text += "ascii";
      break;
    case PlyEncoding::kBinaryLittleEndian:
      text += "binary_little_endian";
      break;
    case PlyEncoding::kBinaryBigEndian:
      text += "binary_big_endian";
      break;
  }
  text += " 1.0\n";
  for (const PlyElement& element : header.elements) {
    text += "element " + element.name + " " + std::to_string(element.count) + "\n";
    for (const PlyProperty& property : element.properties) {
      text += "property ";
      if (property.is_list()) {
        text += std::string("list ") + CanonicalPlyCountType(*property.count_type) + " ";
      }
      text += property.type_name + " " + property.name + "\n";
    }
  }
  return text + "end_header\n";
}

// Reads fixed-size integers from a binary PLY body.
class PlyByteReader {
 public:
  PlyByteReader(std::string_view bytes, bool big_endian) : bytes_(bytes), big_endian_(big_endian) {}

  std::size_t remaining() const { return bytes_.size() - pos_; }
  bool Skip(std::uint64_t count) {
    if (count > remaining()) return false;
    pos_ += static_cast<std::size_t>(count);
    return true;
  }
  bool ReadInteger(PlyType type, long long* value) {
    const std::size_t size = PlyTypeSize(type);
    if (size > remaining()) return false;
    std::uint64_t bits = 0;
    for (std::size_t i = 0; i < size; ++i) {
      const std::size_t byte = big_endian_ ? i : size - 1 - i;
      bits = (bits << 8) | static_cast<unsigned char>(bytes_[pos_ + byte]);
    }
    pos_ += size;
    const std::uint64_t sign_bit = std::uint64_t{1} << (8 * size - 1);
    if (IsPlySigned(type) && (bits & sign_bit)) {
      *value = static_cast<long long>(bits) - static_cast<long long>(sign_bit << 1);
    } else {
      *value = static_cast<long long>(bits);
    }
    return true;
  }

 private:
  std::string_view bytes_;
  bool big_endian_;
  std::size_t pos_ = 0;
};

// Walks a PLY body (binary or ASCII) over the checked header's elements, making sure every
// record is complete and well-formed, that list counts are sane, and counting triangles.
class PlyBodyChecker {
 public:
  PlyBodyChecker(const PlyHeader& header, std::string_view body, const MeshLimits& limits)
      : header_(header), body_(body), limits_(limits) {}

  Status Run() { return header_.encoding == PlyEncoding::kAscii ? CheckAscii() : CheckBinary(); }

 private:
  Status CheckBinary();
  Status CheckBinaryRecord(PlyByteReader* reader, const PlyElement& element, std::uint64_t r);
  Status CheckAscii();
  Status CheckAsciiValue(const PlyElement& element, std::uint64_t r, const PlyProperty& property,
                         PlyType type, std::string_view token) const;
  Status CountFace(long long size);
  Status EndsInside(const PlyElement& element, std::uint64_t r) const {
    return Status::InvalidArgument("the PLY data ends inside " + element.name + " " +
                                   std::to_string(r) + " of " + std::to_string(element.count));
  }

  const PlyHeader& header_;
  std::string_view body_;
  MeshLimits limits_;
  std::size_t num_triangles_ = 0;
};

Status PlyBodyChecker::CountFace(long long size) {
  return CountFaceTriangles(size, "the PLY data", limits_.max_triangles, &num_triangles_);
}

Status PlyBodyChecker::CheckBinary() {
  PlyByteReader reader(body_, header_.encoding == PlyEncoding::kBinaryBigEndian);
  for (const PlyElement& element : header_.elements) {
    const bool has_list = std::any_of(element.properties.begin(), element.properties.end(),
                                      [](const PlyProperty& p) { return p.is_list(); });
    if (!has_list) {
      std::uint64_t record_size = 0;
      for (const PlyProperty& property : element.properties) {
        record_size += PlyTypeSize(property.type);
      }
      if (record_size > 0 && element.count > reader.remaining() / record_size) {
        return EndsInside(element, reader.remaining() / record_size);
      }
      reader.Skip(record_size * element.count);
      continue;
    }
    for (std::uint64_t r = 0; r < element.count; ++r) {
      DEFORM_RETURN_IF_ERROR(CheckBinaryRecord(&reader, element, r));
    }
  }
  return Status::Ok();
}

Status PlyBodyChecker::CheckBinaryRecord(PlyByteReader* reader, const PlyElement& element,
                                         std::uint64_t r) {
  for (const PlyProperty& property : element.properties) {
    if (!property.is_list()) {
      if (!reader->Skip(PlyTypeSize(property.type))) return EndsInside(element, r);
      continue;
    }
    long long size = 0;
    if (!reader->ReadInteger(*property.count_type, &size)) return EndsInside(element, r);
    if (size < 0 || size > std::numeric_limits<int>::max()) {
      return Status::InvalidArgument("PLY " + element.name + " " + std::to_string(r) +
                                     " has an invalid list size " + std::to_string(size));
    }
    if (static_cast<std::uint64_t>(size) > reader->remaining() / PlyTypeSize(property.type)) {
      return EndsInside(element, r);
    }
    reader->Skip(static_cast<std::uint64_t>(size) * PlyTypeSize(property.type));
    if (IsVertexIndexList(element, property)) DEFORM_RETURN_IF_ERROR(CountFace(size));
  }
  return Status::Ok();
}

Status PlyBodyChecker::CheckAsciiValue(const PlyElement& element, std::uint64_t r,
                                       const PlyProperty& property, PlyType type,
                                       std::string_view token) const {
  const auto invalid = [&] {
    return Status::InvalidArgument("PLY " + element.name + " " + std::to_string(r) + ": property " +
                                   Quoted(property.name) + " has an invalid value " +
                                   Quoted(token));
  };
  if (IsPlyInteger(type)) {
    long long value = 0;
    // The reader extracts some integers into an int.
    const bool ok = ParseInteger(token, &value) && value >= std::numeric_limits<int>::min() &&
                    value <= std::numeric_limits<int>::max();
    return ok ? Status::Ok() : invalid();
  }
  double value = 0.0;
  const RealParse parse = ParseReal(token, &value);
  if (parse == RealParse::kNonFinite && element.name == "vertex" &&
      IsOneOf(property.name, {"x", "y", "z"})) {
    return NonFiniteCoordinate(static_cast<std::size_t>(r), token, "PLY data");
  }
  return parse == RealParse::kOk ? Status::Ok() : invalid();
}

Status PlyBodyChecker::CheckAscii() {
  TokenReader tokens(body_, 1);
  std::string_view token;
  for (const PlyElement& element : header_.elements) {
    for (std::uint64_t r = 0; r < element.count; ++r) {
      for (const PlyProperty& property : element.properties) {
        if (!tokens.Next(&token)) return EndsInside(element, r);
        if (!property.is_list()) {
          DEFORM_RETURN_IF_ERROR(CheckAsciiValue(element, r, property, property.type, token));
          continue;
        }
        long long size = 0;
        if (!ParseInteger(token, &size) || size < 0 || size > std::numeric_limits<int>::max()) {
          return Status::InvalidArgument("PLY " + element.name + " " + std::to_string(r) +
                                         " has an invalid list size " + Quoted(token));
        }
        for (long long i = 0; i < size; ++i) {
          if (!tokens.Next(&token)) return EndsInside(element, r);
          DEFORM_RETURN_IF_ERROR(CheckAsciiValue(element, r, property, property.type, token));
        }
        if (IsVertexIndexList(element, property)) DEFORM_RETURN_IF_ERROR(CountFace(size));
      }
    }
  }
  return Status::Ok();
}

}  // namespace

Status ReadPly(std::string_view bytes, const MeshLimits& limits, SoupImporter* importer) {
  DEFORM_ASSIGN_OR_RETURN(PlyHeader header, PlyHeaderParser(bytes).Run());
  DEFORM_RETURN_IF_ERROR(CheckPlyLayout(limits, &header));
  const std::string_view body = bytes.substr(header.body_offset);
  DEFORM_RETURN_IF_ERROR(PlyBodyChecker(header, body, limits).Run());

  std::string canonical = CanonicalPlyHeader(header);
  canonical.append(body.data(), body.size());
  // The ASCII reader reports "unexpected end of file" if an element ends exactly at the end.
  if (header.encoding == PlyEncoding::kAscii) canonical += '\n';
  DEFORM_RETURN_IF_ERROR(ReadWithOpenMesh(canonical, MeshFormat::kPly, false, importer));
  const std::optional<std::size_t> face = FindPlyElement(header, "face");
  return CheckImportedCounts(*importer, MeshFormat::kPly,
                             header.elements[*FindPlyElement(header, "vertex")].count,
                             face ? static_cast<std::size_t>(header.elements[*face].count) : 0);
}

}  // namespace deform::mesh_io_internal
