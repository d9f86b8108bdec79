#include "file_bytes.h"

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <new>
#include <system_error>

namespace deform::io_internal {

StatusOr<std::string> ReadFileBytes(const std::string& path, const char* what) {
  std::error_code error;
  if (std::filesystem::is_directory(path, error)) {
    return Status::InvalidArgument(path + " is a directory, not a " + what);
  }
  std::ifstream file(path, std::ios::binary);
  if (!file) {
    return Status::NotFound("cannot open " + std::string(what) + " " + path + ": " +
                            std::strerror(errno));
  }
  try {
    std::string bytes;
    file.seekg(0, std::ios::end);
    const std::streamoff size = file.tellg();
    file.seekg(0, std::ios::beg);
    if (size >= 0) {
      bytes.resize(static_cast<std::size_t>(size));
      file.read(bytes.data(), size);
      bytes.resize(static_cast<std::size_t>(file.gcount()));
    } else {  // not seekable (a pipe, say)
      file.clear();
      bytes.assign(std::istreambuf_iterator<char>(file), std::istreambuf_iterator<char>());
    }
    if (file.bad()) return Status::Internal("reading " + path + " failed");
    return bytes;
  } catch (const std::bad_alloc&) {
    return Status::ResourceExhausted(path + " is too large to read");
  }
}

}  // namespace deform::io_internal
