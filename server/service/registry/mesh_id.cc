#include "service/registry/mesh_id.h"

#include <sys/random.h>

#include <cerrno>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>

namespace deform::service {
namespace {

constexpr std::string_view kPrefix = "mesh-";
constexpr std::size_t kRandomBytes = 16;

void FillRandom(unsigned char* bytes, std::size_t size) {
  std::size_t filled = 0;
  while (filled < size) {
    const ssize_t got = getrandom(bytes + filled, size - filled, 0);
    if (got < 0) {
      if (errno == EINTR) continue;
      std::perror("deformd: getrandom");
      std::abort();
    }
    filled += static_cast<std::size_t>(got);
  }
}

}  // namespace

std::string NewMeshId() {
  unsigned char bytes[kRandomBytes];
  FillRandom(bytes, sizeof bytes);
  static constexpr char kHex[] = "0123456789abcdef";
  std::string id(kPrefix);
  id.reserve(kPrefix.size() + 2 * kRandomBytes);
  for (const unsigned char byte : bytes) {
    id.push_back(kHex[byte >> 4]);
    id.push_back(kHex[byte & 0xf]);
  }
  return id;
}

bool LooksLikeMeshId(std::string_view text) {
  if (text.size() != kPrefix.size() + 2 * kRandomBytes) return false;
  if (text.substr(0, kPrefix.size()) != kPrefix) return false;
  for (const char c : text.substr(kPrefix.size())) {
    if (!((c >= '0' && c <= '9') || (c >= 'a' && c <= 'f'))) return false;
  }
  return true;
}

}  // namespace deform::service
