#include "core/io/declared_mesh_size.h"

#include <cctype>
#include <cstdint>
#include <cstring>
#include <limits>

namespace deform {
namespace {

// The lines of `text`, one at a time, without allocating.
class Lines {
 public:
  explicit Lines(std::string_view text) : rest_(text) {}
  bool Next(std::string_view* line) {
    if (rest_.empty()) return false;
    const std::size_t end = rest_.find('\n');
    *line = rest_.substr(0, end);
    rest_ = end == std::string_view::npos ? std::string_view() : rest_.substr(end + 1);
    if (!line->empty() && line->back() == '\r') line->remove_suffix(1);
    return true;
  }

 private:
  std::string_view rest_;
};

std::string_view TrimLeft(std::string_view text) {
  while (!text.empty() && std::isspace(static_cast<unsigned char>(text.front()))) {
    text.remove_prefix(1);
  }
  return text;
}

// The next whitespace-separated word of *text, removed from it.
std::string_view NextWord(std::string_view* text) {
  *text = TrimLeft(*text);
  std::size_t end = 0;
  while (end < text->size() && !std::isspace(static_cast<unsigned char>((*text)[end]))) ++end;
  const std::string_view word = text->substr(0, end);
  text->remove_prefix(end);
  return word;
}

// A non-negative decimal count; nullopt for anything else or an overflow.
std::optional<std::size_t> Count(std::string_view word) {
  if (word.empty() || word.size() > 18) return std::nullopt;
  std::size_t value = 0;
  for (const char c : word) {
    if (c < '0' || c > '9') return std::nullopt;
    value = value * 10 + static_cast<std::size_t>(c - '0');
  }
  return value;
}

std::optional<DeclaredMeshSize> Off(std::string_view bytes) {
  Lines lines(bytes);
  std::string_view line;
  bool keyword = false;
  while (lines.Next(&line)) {
    std::string_view rest = TrimLeft(line);
    if (rest.empty() || rest.front() == '#') continue;
    if (!keyword) {
      const std::string_view word = NextWord(&rest);
      if (word.size() < 3 || word.substr(word.size() - 3) != "OFF") return std::nullopt;
      keyword = true;
      rest = TrimLeft(rest);
      if (rest.empty() || rest.front() == '#') continue;  // counts on the next line
    }
    const auto vertices = Count(NextWord(&rest));
    const auto faces = Count(NextWord(&rest));
    if (!vertices || !faces) return std::nullopt;
    return DeclaredMeshSize{*vertices, *faces};
  }
  return std::nullopt;
}

std::optional<DeclaredMeshSize> Ply(std::string_view bytes) {
  Lines lines(bytes);
  std::string_view line;
  if (!lines.Next(&line) || TrimLeft(line).substr(0, 3) != "ply") return std::nullopt;
  std::optional<std::size_t> vertices, faces;
  while (lines.Next(&line)) {
    std::string_view rest = line;
    const std::string_view word = NextWord(&rest);
    if (word == "end_header") break;
    if (word != "element") continue;
    const std::string_view name = NextWord(&rest);
    const auto count = Count(NextWord(&rest));
    if (!count) return std::nullopt;
    if (name == "vertex") vertices = count;
    if (name == "face") faces = count;
  }
  if (!vertices || !faces) return std::nullopt;
  return DeclaredMeshSize{*vertices, *faces};
}

std::optional<DeclaredMeshSize> Stl(std::string_view bytes) {
  if (bytes.size() >= 84) {
    std::uint32_t triangles = 0;
    for (int i = 3; i >= 0; --i) {
      triangles = (triangles << 8) | static_cast<unsigned char>(bytes[80 + i]);
    }
    if (bytes.size() == 84 + std::size_t{50} * triangles) {
      return DeclaredMeshSize{std::size_t{3} * triangles, triangles};
    }
  }
  // ASCII: one "facet" line per triangle.
  Lines lines(bytes);
  std::string_view line;
  std::size_t facets = 0;
  while (lines.Next(&line)) {
    std::string_view rest = line;
    if (NextWord(&rest) == "facet") ++facets;
  }
  if (facets == 0) return std::nullopt;
  return DeclaredMeshSize{3 * facets, facets};
}

std::optional<DeclaredMeshSize> Obj(std::string_view bytes) {
  Lines lines(bytes);
  std::string_view line;
  DeclaredMeshSize size;
  while (lines.Next(&line)) {
    std::string_view rest = line;
    const std::string_view word = NextWord(&rest);
    if (word == "v") ++size.vertices;
    if (word == "f") ++size.faces;
  }
  if (size.vertices == 0 && size.faces == 0) return std::nullopt;
  return size;
}

}  // namespace

std::optional<DeclaredMeshSize> ReadDeclaredMeshSize(std::string_view bytes, MeshFormat format) {
  switch (format) {
    case MeshFormat::kOff:
      return Off(bytes);
    case MeshFormat::kPly:
      return Ply(bytes);
    case MeshFormat::kStl:
      return Stl(bytes);
    case MeshFormat::kObj:
      return Obj(bytes);
  }
  return std::nullopt;
}

}  // namespace deform
