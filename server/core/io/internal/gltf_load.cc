#include "gltf_load.h"

#include <cstdint>
#include <limits>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "mesh_io_internal.h"

namespace deform::gltf_internal {
namespace {

using mesh_io_internal::Quoted;

constexpr std::uint32_t kGlbMagic = 0x46546C67;     // "glTF"
constexpr std::uint32_t kChunkJson = 0x4E4F534A;    // "JSON"
constexpr std::uint32_t kChunkBinary = 0x004E4942;  // "BIN\0"

std::uint32_t ReadU32(std::string_view bytes, std::size_t offset) {
  std::uint32_t value = 0;
  for (int b = 3; b >= 0; --b) {
    value = (value << 8) | static_cast<unsigned char>(bytes[offset + static_cast<std::size_t>(b)]);
  }
  return value;
}

// A .glb split into its chunks, checked against the GLB layout of the glTF 2.0 spec.
struct GlbChunks {
  std::string_view json;
  bool has_binary = false;
};

StatusOr<GlbChunks> SplitGlb(std::string_view bytes) {
  if (bytes.size() < 20) {
    return Status::InvalidArgument("the .glb is truncated: " + std::to_string(bytes.size()) +
                                   " bytes, less than its 12-byte header and a chunk header");
  }
  const std::uint32_t version = ReadU32(bytes, 4);
  const std::uint32_t length = ReadU32(bytes, 8);
  if (version != 2) {
    return Status::InvalidArgument("the .glb is version " + std::to_string(version) +
                                   "; only glTF 2 is supported");
  }
  if (length != bytes.size()) {
    return Status::InvalidArgument("the .glb header states " + std::to_string(length) +
                                   " bytes but " + std::to_string(bytes.size()) +
                                   " were given (truncated or padded)");
  }
  const std::uint64_t json_length = ReadU32(bytes, 12);
  if (ReadU32(bytes, 16) != kChunkJson) {
    return Status::InvalidArgument("the .glb's first chunk is not its JSON chunk");
  }
  const std::uint64_t json_end = 20 + json_length;
  if (json_length == 0 || json_end > bytes.size() || json_end % 4 != 0) {
    return Status::InvalidArgument("the .glb's JSON chunk of " + std::to_string(json_length) +
                                   " bytes does not fit its " + std::to_string(bytes.size()) +
                                   " bytes (or is not 4-byte aligned)");
  }
  GlbChunks chunks;
  chunks.json = bytes.substr(20, json_length);
  if (json_end == bytes.size()) return chunks;
  if (json_end + 8 > bytes.size()) {
    return Status::InvalidArgument("the .glb ends inside the header of its second chunk");
  }
  const std::uint64_t binary_length = ReadU32(bytes, json_end);
  if (ReadU32(bytes, json_end + 4) != kChunkBinary) {
    return Status::InvalidArgument("the .glb's second chunk is not a BIN chunk");
  }
  if (json_end + 8 + binary_length != bytes.size() || binary_length % 4 != 0) {
    return Status::InvalidArgument("the .glb's BIN chunk states " + std::to_string(binary_length) +
                                   " bytes, which do not end the file (truncated, or "
                                   "unaligned)");
  }
  chunks.has_binary = true;
  return chunks;
}

// Nesting depth of the JSON text's arrays and objects, by a scan that skips strings; stops
// counting once past `limit`.
int JsonNestingDepth(std::string_view text, int limit) {
  int depth = 0;
  int deepest = 0;
  bool in_string = false;
  for (std::size_t i = 0; i < text.size() && deepest <= limit; ++i) {
    const char c = text[i];
    if (in_string) {
      if (c == '\\') {
        ++i;
      } else if (c == '"') {
        in_string = false;
      }
    } else if (c == '"') {
      in_string = true;
    } else if (c == '[' || c == '{') {
      deepest = std::max(deepest, ++depth);
    } else if (c == ']' || c == '}') {
      --depth;
    }
  }
  return deepest;
}

// The data URI media types that tinygltf decodes (anything else it would take for a file name).
bool IsDecodableDataUri(const std::string& uri) {
  for (const char* prefix :
       {"data:application/octet-stream;base64,", "data:application/gltf-buffer;base64,",
        "data:image/jpeg;base64,", "data:image/png;base64,", "data:image/bmp;base64,",
        "data:image/gif;base64,", "data:text/plain;base64,"}) {
    if (uri.rfind(prefix, 0) == 0) return true;
  }
  return false;
}

Status CheckUri(const nlohmann::json& item, const std::string& what) {
  if (!item.is_object() || !item.contains("uri")) return Status::Ok();
  if (!item["uri"].is_string()) return Status::InvalidArgument(what + "'s uri is not a string");
  const std::string uri = item["uri"].get<std::string>();
  if (uri.rfind("data:", 0) == 0) {
    if (IsDecodableDataUri(uri)) return Status::Ok();
    return Status::InvalidArgument(what + " has a data URI of an unsupported kind " +
                                   Quoted(uri.substr(0, uri.find(',') + 1)) +
                                   " (expected base64 application/octet-stream or "
                                   "application/gltf-buffer)");
  }
  return Status::InvalidArgument(what + " refers to the external file " + Quoted(uri) +
                                 ": an uploaded glTF must hold all its data (data URIs in a "
                                 ".gltf, or a .glb); nothing else is read");
}

// Extensions that change nothing the import reads (materials, textures, lights).
bool IsHarmlessExtension(const std::string& name) {
  return name.rfind("KHR_materials_", 0) == 0 || name.rfind("KHR_texture_", 0) == 0 ||
         name == "KHR_lights_punctual" || name == "EXT_texture_webp";
}

bool IsUnsigned(const nlohmann::json& object, const char* key) {
  return !object.contains(key) || object[key].is_number_unsigned();
}

// Each bufferView lies inside its buffer (by the buffers' stated byteLength; the loaded data is
// checked against the stated length by tinygltf and again by the accessor reader).
Status CheckBufferViews(const nlohmann::json& doc) {
  if (!doc.contains("bufferViews")) return Status::Ok();
  const nlohmann::json& views = doc["bufferViews"];
  const nlohmann::json* buffers = doc.contains("buffers") ? &doc["buffers"] : nullptr;
  if (!views.is_array()) return Status::InvalidArgument("glTF 'bufferViews' is not an array");
  for (std::size_t v = 0; v < views.size(); ++v) {
    const nlohmann::json& view = views[v];
    const std::string what = "bufferView " + std::to_string(v);
    if (!view.is_object() || !view.contains("buffer") || !view["buffer"].is_number_unsigned() ||
        !view.contains("byteLength") || !view["byteLength"].is_number_unsigned() ||
        !IsUnsigned(view, "byteOffset")) {
      return Status::InvalidArgument(what +
                                     " needs a buffer index and a byteLength (and a "
                                     "non-negative integer byteOffset)");
    }
    const std::uint64_t buffer = view["buffer"].get<std::uint64_t>();
    if (buffers == nullptr || !buffers->is_array() || buffer >= buffers->size() ||
        !(*buffers)[buffer].is_object() || !(*buffers)[buffer].contains("byteLength") ||
        !(*buffers)[buffer]["byteLength"].is_number_unsigned()) {
      return Status::InvalidArgument(what + " refers to buffer " + std::to_string(buffer) +
                                     ", which does not exist or has no byteLength");
    }
    const std::uint64_t buffer_length = (*buffers)[buffer]["byteLength"].get<std::uint64_t>();
    const std::uint64_t offset =
        view.contains("byteOffset") ? view["byteOffset"].get<std::uint64_t>() : 0;
    const std::uint64_t length = view["byteLength"].get<std::uint64_t>();
    if (offset > buffer_length || length > buffer_length - offset) {
      return Status::InvalidArgument(what + " (offset " + std::to_string(offset) + ", " +
                                     std::to_string(length) + " bytes) overruns buffer " +
                                     std::to_string(buffer) + " of " +
                                     std::to_string(buffer_length) + " bytes");
    }
  }
  return Status::Ok();
}

Status PreflightJson(std::string_view text) {
  if (JsonNestingDepth(text, kMaxJsonDepth) > kMaxJsonDepth) {
    return Status::InvalidArgument("the glTF JSON nests deeper than " +
                                   std::to_string(kMaxJsonDepth) + " levels");
  }
  const nlohmann::json doc = nlohmann::json::parse(text.begin(), text.end(), nullptr,
                                                   /*allow_exceptions=*/false);
  if (doc.is_discarded()) return Status::InvalidArgument("the glTF JSON does not parse");
  if (!doc.is_object()) return Status::InvalidArgument("the glTF JSON is not an object");
  if (!doc.contains("asset") || !doc["asset"].is_object() || !doc["asset"].contains("version") ||
      !doc["asset"]["version"].is_string()) {
    return Status::InvalidArgument("not a glTF: no asset.version");
  }
  const std::string version = doc["asset"]["version"].get<std::string>();
  if (version.rfind("2.", 0) != 0) {
    return Status::InvalidArgument("glTF version " + Quoted(version) + " is not supported (2.x)");
  }
  if (doc.contains("extensionsRequired") && doc["extensionsRequired"].is_array()) {
    for (const nlohmann::json& name : doc["extensionsRequired"]) {
      if (!name.is_string() || !IsHarmlessExtension(name.get<std::string>())) {
        return Status::InvalidArgument("the glTF requires extension " + Quoted(name.dump()) +
                                       ", which the import does not support (export without "
                                       "mesh compression or quantization)");
      }
    }
  }
  for (const char* array : {"buffers", "images"}) {
    if (!doc.contains(array)) continue;
    if (!doc[array].is_array()) {
      return Status::InvalidArgument(std::string("glTF '") + array + "' is not an array");
    }
    const std::string noun = std::string(array) == "buffers" ? "buffer " : "image ";
    for (std::size_t i = 0; i < doc[array].size(); ++i) {
      DEFORM_RETURN_IF_ERROR(CheckUri(doc[array][i], noun + std::to_string(i)));
    }
  }
  return CheckBufferViews(doc);
}

// File callbacks for tinygltf that refuse every path (PreflightJson already refused external
// URIs; these make sure that nothing is read should a path get through).
bool NoFileExists(const std::string&, void*) { return false; }
std::string KeepPath(const std::string& path, void*) { return path; }
bool NoFileRead(std::vector<unsigned char>*, std::string* error, const std::string& path, void*) {
  if (error != nullptr) *error = "reading files is disabled (" + path + ")";
  return false;
}
bool NoFileWrite(std::string* error, const std::string& path, const std::vector<unsigned char>&,
                 void*) {
  if (error != nullptr) *error = "writing files is disabled (" + path + ")";
  return false;
}

// Images are not needed: they are skipped, never decoded.
bool IgnoreImage(tinygltf::Image*, const int, std::string*, std::string*, int, int,
                 const unsigned char*, int, void*) {
  return true;
}

std::string FirstLine(const std::string& text) {
  std::string line = text.substr(0, text.find('\n'));
  return line.empty() ? "unknown error" : line.substr(0, 200);
}

}  // namespace

bool IsGlb(std::string_view bytes) { return bytes.size() >= 4 && ReadU32(bytes, 0) == kGlbMagic; }

Status LoadGltfModel(std::string_view bytes, tinygltf::Model* model) {
  if (bytes.empty()) return Status::InvalidArgument("the glTF data is empty");
  if (bytes.size() >= std::numeric_limits<unsigned int>::max()) {
    return Status::ResourceExhausted("the glTF data is 4 GB or larger");
  }
  const bool glb = IsGlb(bytes);
  std::string_view json = bytes;
  if (glb) {
    DEFORM_ASSIGN_OR_RETURN(const GlbChunks chunks, SplitGlb(bytes));
    json = chunks.json;
  }
  DEFORM_RETURN_IF_ERROR(PreflightJson(json));

  tinygltf::TinyGLTF loader;
  loader.SetFsCallbacks({&NoFileExists, &KeepPath, &NoFileRead, &NoFileWrite, nullptr});
  loader.SetImageLoader(&IgnoreImage, nullptr);
  std::string error;
  std::string warning;
  const bool loaded =
      glb ? loader.LoadBinaryFromMemory(model, &error, &warning,
                                        reinterpret_cast<const unsigned char*>(bytes.data()),
                                        static_cast<unsigned int>(bytes.size()), "")
          : loader.LoadASCIIFromString(model, &error, &warning, json.data(),
                                       static_cast<unsigned int>(json.size()), "");
  if (!loaded) return Status::InvalidArgument("glTF: " + FirstLine(error));
  return Status::Ok();
}

}  // namespace deform::gltf_internal
