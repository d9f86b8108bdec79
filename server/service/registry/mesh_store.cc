#include "service/registry/mesh_store.h"

#include <fcntl.h>
#include <openssl/crypto.h>
#include <openssl/evp.h>
#include <openssl/hmac.h>
#include <openssl/rand.h>
#include <spdlog/spdlog.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "service/access/identity.h"
#include "service/base/log_text.h"
#include "service/registry/mesh_id.h"

namespace deform::service {
namespace {

constexpr std::string_view kMagic = "deformd-store v1\n";       // SHA-256 of the body
constexpr std::string_view kKeyedMagic = "deformd-store v2\n";  // HMAC-SHA256 of the body
constexpr std::size_t kKeyBytes = 32;
constexpr std::size_t kDigestBytes = 32;
// A shared store's pending file this old has no writer left (a load's build takes minutes at most).
constexpr long kSharedPendingAgeSeconds = 3600;
// Enough of an entry's beginning for its id and tenant (PeekTenant).
constexpr std::size_t kPeekBytes = 4096;

std::string ErrnoText() { return std::strerror(errno); }

template <typename T>
std::string LittleEndian(T value) {
  std::string bytes(sizeof(T), '\0');
  for (std::size_t i = 0; i < sizeof(T); ++i) {
    bytes[i] = static_cast<char>((static_cast<std::uint64_t>(value) >> (8 * i)) & 0xff);
  }
  return bytes;
}

// The entry's seal: the SHA-256 of `body`, or its HMAC-SHA256 under `key` when there is one.
std::string SealOf(std::string_view body, const std::string& key) {
  unsigned char digest[EVP_MAX_MD_SIZE];
  unsigned int length = 0;
  if (key.empty()) {
    EVP_Digest(body.data(), body.size(), digest, &length, EVP_sha256(), nullptr);
  } else {
    HMAC(EVP_sha256(), key.data(), static_cast<int>(key.size()),
         reinterpret_cast<const unsigned char*>(body.data()), body.size(), digest, &length);
  }
  return std::string(reinterpret_cast<const char*>(digest), length);
}

// Writes pieces to a file descriptor, then their seal.
// Writes pieces to a file descriptor while sealing them (SealOf, incrementally).
class HashingWriter {
 public:
  HashingWriter(int fd, const std::string& key) : fd_(fd), context_(EVP_MD_CTX_new()) {
    if (key.empty()) {
      EVP_DigestInit_ex(context_, EVP_sha256(), nullptr);
    } else {
      pkey_ = EVP_PKEY_new_raw_private_key(
          EVP_PKEY_HMAC, nullptr, reinterpret_cast<const unsigned char*>(key.data()), key.size());
      EVP_DigestSignInit(context_, nullptr, EVP_sha256(), nullptr, pkey_);
    }
  }
  ~HashingWriter() {
    EVP_MD_CTX_free(context_);
    EVP_PKEY_free(pkey_);
  }
  HashingWriter(const HashingWriter&) = delete;
  HashingWriter& operator=(const HashingWriter&) = delete;
  bool Write(std::string_view bytes) {
    if (pkey_ != nullptr) {
      EVP_DigestSignUpdate(context_, bytes.data(), bytes.size());
    } else {
      EVP_DigestUpdate(context_, bytes.data(), bytes.size());
    }
    return WriteRaw(bytes);
  }
  bool WriteDigest() {
    unsigned char digest[EVP_MAX_MD_SIZE];
    std::size_t length = sizeof digest;
    if (pkey_ != nullptr) {
      if (EVP_DigestSignFinal(context_, digest, &length) != 1) return false;
    } else {
      unsigned int digest_length = 0;
      EVP_DigestFinal_ex(context_, digest, &digest_length);
      length = digest_length;
    }
    return WriteRaw(std::string_view(reinterpret_cast<const char*>(digest), length));
  }

 private:
  bool WriteRaw(std::string_view bytes) {
    while (!bytes.empty()) {
      const ssize_t written = ::write(fd_, bytes.data(), bytes.size());
      if (written < 0) {
        if (errno == EINTR) continue;
        return false;
      }
      bytes.remove_prefix(static_cast<std::size_t>(written));
    }
    return true;
  }
  int fd_;
  EVP_MD_CTX* context_;
  EVP_PKEY* pkey_ = nullptr;
};

// Reads the little-endian integer of T at *offset; false past the end.
template <typename T>
bool ReadInteger(std::string_view data, std::size_t* offset, T* value) {
  if (data.size() - *offset < sizeof(T)) return false;
  std::uint64_t result = 0;
  for (std::size_t i = 0; i < sizeof(T); ++i) {
    result |= std::uint64_t{static_cast<unsigned char>(data[*offset + i])} << (8 * i);
  }
  *offset += sizeof(T);
  *value = static_cast<T>(result);
  return true;
}

template <typename Length>
bool ReadField(std::string_view data, std::size_t* offset, std::string_view* field) {
  Length length = 0;
  if (!ReadInteger(data, offset, &length)) return false;
  if (data.size() - *offset < length) return false;
  *field = data.substr(*offset, length);
  *offset += length;
  return true;
}

StatusOr<StoredMesh> ParseEntry(std::string_view data, const std::string& key) {
  if (data.size() < kMagic.size() + kDigestBytes ||
      (data.substr(0, kMagic.size()) != kMagic && data.substr(0, kMagic.size()) != kKeyedMagic)) {
    return Status::InvalidArgument("not a deformd store entry (bad magic or too short)");
  }
  const bool keyed = data.substr(0, kMagic.size()) == kKeyedMagic;
  if (keyed && key.empty()) {
    return Status::InvalidArgument("it is authenticated with a key and no --store-key was given");
  }
  if (!keyed && !key.empty()) {
    return Status::InvalidArgument(
        "it is not authenticated (written without --store-key): its owner cannot be trusted");
  }
  const std::string_view body = data.substr(0, data.size() - kDigestBytes);
  const std::string seal = SealOf(body, key);
  if (seal.size() != kDigestBytes ||
      CRYPTO_memcmp(seal.data(), data.data() + body.size(), kDigestBytes) != 0) {
    return Status::InvalidArgument(
        keyed ? "authentication code mismatch (the entry or its owner was edited, or another key)"
              : "checksum mismatch (truncated or altered)");
  }
  std::size_t offset = kMagic.size();
  std::string_view id, tenant, header, mesh;
  if (!ReadField<std::uint32_t>(body, &offset, &id) ||
      !ReadField<std::uint32_t>(body, &offset, &tenant) ||
      !ReadField<std::uint64_t>(body, &offset, &header) ||
      !ReadField<std::uint64_t>(body, &offset, &mesh) || offset != body.size()) {
    return Status::InvalidArgument("malformed field lengths");
  }
  StoredMesh stored;
  stored.id = std::string(id);
  stored.tenant = std::string(tenant);
  if (!LooksLikeMeshId(stored.id)) return Status::InvalidArgument("malformed mesh id");
  if (!IsValidTenantName(stored.tenant)) return Status::InvalidArgument("malformed tenant");
  if (!stored.header.ParseFromArray(header.data(), static_cast<int>(header.size()))) {
    return Status::InvalidArgument("the LoadMesh header does not parse");
  }
  stored.mesh_bytes = std::string(mesh);
  return stored;
}

void SyncDirectory(const std::string& dir) {
  const int dir_fd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (dir_fd >= 0) {
    ::fsync(dir_fd);
    ::close(dir_fd);
  }
}

// The whole content of the regular file `path`; an error for anything else (a FIFO, a
// directory, a device, a symbolic link), without blocking on it.
StatusOr<std::string> ReadRegularFile(const std::string& path) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_NOFOLLOW | O_CLOEXEC);
  if (fd < 0) return Status::NotFound("cannot open it: " + ErrnoText());
  struct stat info {};
  if (::fstat(fd, &info) != 0 || !S_ISREG(info.st_mode)) {
    ::close(fd);
    return Status::InvalidArgument("it is not a regular file");
  }
  std::string data;
  char buffer[1 << 16];
  for (;;) {
    const ssize_t n = ::read(fd, buffer, sizeof buffer);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) {
      const std::string why = ErrnoText();
      ::close(fd);
      return Status::NotFound("cannot read it: " + why);
    }
    if (n == 0) break;
    data.append(buffer, static_cast<std::size_t>(n));
  }
  ::close(fd);
  return data;
}

}  // namespace

StatusOr<std::string> MeshStore::ReadOrCreateKey(const std::string& path, const std::string& dir) {
  std::error_code error;
  const auto key_dir =
      std::filesystem::weakly_canonical(std::filesystem::absolute(path).parent_path(), error);
  const auto store_dir = std::filesystem::weakly_canonical(std::filesystem::absolute(dir), error);
  if (key_dir == store_dir) {
    return Status::FailedPrecondition("--store-key '" + path +
                                      "' must be outside the store directory (a key beside the "
                                      "entries authenticates nothing)");
  }
  int fd = ::open(path.c_str(), O_RDONLY | O_NOFOLLOW | O_CLOEXEC);
  if (fd < 0 && errno == ENOENT) {
    // Written beside it, then linked into place: replicas starting together all read one whole
    // key (link() refuses to replace the one another replica published first).
    unsigned char fresh[kKeyBytes];
    if (RAND_bytes(fresh, sizeof fresh) != 1) return Status::Internal("no random bytes for a key");
    const std::string draft = path + "." + NewMeshId().substr(5) + ".new";
    const int out = ::open(draft.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0600);
    if (out < 0) {
      return Status::FailedPrecondition("cannot create the store key '" + path +
                                        "': " + ErrnoText());
    }
    const bool written = ::write(out, fresh, sizeof fresh) == static_cast<ssize_t>(sizeof fresh) &&
                         ::fsync(out) == 0;
    ::close(out);
    const bool published = written && ::link(draft.c_str(), path.c_str()) == 0;
    const int link_error = errno;
    ::unlink(draft.c_str());
    if (!written || (!published && link_error != EEXIST)) {
      return Status::FailedPrecondition("cannot write the store key '" + path + "'");
    }
    if (published) spdlog::info("store: created the key '{}'", EscapeForLog(path));
    fd = ::open(path.c_str(), O_RDONLY | O_NOFOLLOW | O_CLOEXEC);
  }
  if (fd < 0) {
    return Status::FailedPrecondition("cannot open the store key '" + path + "': " + ErrnoText());
  }
  struct stat info {};
  std::string key(kKeyBytes + 1, '\0');
  const ssize_t n =
      ::fstat(fd, &info) == 0 && S_ISREG(info.st_mode) ? ::read(fd, key.data(), key.size()) : -1;
  ::close(fd);
  if (n != static_cast<ssize_t>(kKeyBytes)) {
    return Status::FailedPrecondition("the store key '" + path + "' is not a file of " +
                                      std::to_string(kKeyBytes) + " bytes");
  }
  if ((info.st_mode & 0077) != 0) {
    return Status::FailedPrecondition("the store key '" + path +
                                      "' is readable by others (chmod 600 it)");
  }
  key.resize(kKeyBytes);
  return key;
}

StatusOr<std::unique_ptr<MeshStore>> MeshStore::Open(const std::string& dir,
                                                     const std::string& key_file, bool shared) {
  if (dir.empty()) return Status::FailedPrecondition("the store directory is empty");
  if (::mkdir(dir.c_str(), 0700) != 0 && errno != EEXIST) {
    return Status::FailedPrecondition("cannot create the store directory '" + dir +
                                      "': " + ErrnoText());
  }
  struct stat info {};
  if (::stat(dir.c_str(), &info) != 0 || !S_ISDIR(info.st_mode)) {
    return Status::FailedPrecondition("the store '" + dir + "' is not a directory");
  }
  if (info.st_uid != ::geteuid()) {
    return Status::FailedPrecondition("the store directory '" + dir + "' belongs to another user");
  }
  if ((info.st_mode & 0777) != 0700 && ::chmod(dir.c_str(), 0700) != 0) {
    return Status::FailedPrecondition("cannot make the store directory '" + dir +
                                      "' private (0700): " + ErrnoText());
  }
  // One server per exclusive store: a second one would delete the first's unfinished entries and
  // unload its meshes' files. Replicas share theirs.
  const std::string lock_path = dir + "/" + std::string(kLockFileName);
  const int lock_fd = ::open(lock_path.c_str(), O_RDWR | O_CREAT | O_CLOEXEC | O_NOFOLLOW, 0600);
  if (lock_fd < 0) {
    return Status::FailedPrecondition("cannot open the store's lock file '" + lock_path +
                                      "': " + ErrnoText());
  }
  if (::flock(lock_fd, (shared ? LOCK_SH : LOCK_EX) | LOCK_NB) != 0) {
    const std::string why = errno != EWOULDBLOCK ? ErrnoText()
                            : shared ? "a deformd without --store-shared uses this store"
                                     : "another deformd uses this store";
    ::close(lock_fd);
    return Status::FailedPrecondition("the store '" + dir + "' is locked (" + lock_path +
                                      "): " + why);
  }
  std::string key;
  if (!key_file.empty()) {
    StatusOr<std::string> read = ReadOrCreateKey(key_file, dir);
    if (!read.ok()) {
      ::close(lock_fd);
      return read.status();
    }
    key = std::move(*read);
  }
  std::unique_ptr<MeshStore> store(new MeshStore(dir, lock_fd, std::move(key), shared));
  // Writable now, not at the first load: a read-only store would fail every load.
  const std::string probe = dir + "/.write-check." + NewMeshId() + ".pending";
  const int probe_fd = ::open(probe.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0600);
  if (probe_fd < 0 || ::fsync(probe_fd) != 0 || ::unlink(probe.c_str()) != 0) {
    const std::string why = ErrnoText();
    if (probe_fd >= 0) ::close(probe_fd);
    return Status::FailedPrecondition("the store '" + dir + "' is not writable: " + why);
  }
  ::close(probe_fd);
  std::error_code error;
  for (const auto& file : std::filesystem::directory_iterator(dir, error)) {
    const std::string name = file.path().filename().string();
    if (name.size() > 9 && name[0] == '.' && name.substr(name.size() - 8) == ".pending") {
      // Shared: only those no replica can still be writing.
      struct stat pending {};
      if (shared && (::stat(file.path().c_str(), &pending) != 0 ||
                     ::time(nullptr) - pending.st_mtime < kSharedPendingAgeSeconds)) {
        continue;
      }
      spdlog::warn("store: deleting the unfinished entry '{}'", EscapeForLog(name));
      std::filesystem::remove(file.path(), error);
    }
  }
  return store;
}

StatusOr<std::string> MeshStore::WritePending(const StoredMesh& mesh) const {
  // Unique: several loads (or replicas) may write the same id at once.
  const std::string path = dir_ + "/." + mesh.id + "." + NewMeshId().substr(5) + ".pending";
  const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0600);
  if (fd < 0) {
    spdlog::error("store: cannot create '{}': {}", EscapeForLog(path), ErrnoText());
    return Status::Internal("the server cannot keep the mesh in its store (see its log)");
  }
  const std::string header = mesh.header.SerializeAsString();
  HashingWriter writer(fd, key_);
  bool ok = writer.Write(key_.empty() ? kMagic : kKeyedMagic) &&
            writer.Write(LittleEndian(static_cast<std::uint32_t>(mesh.id.size()))) &&
            writer.Write(mesh.id) &&
            writer.Write(LittleEndian(static_cast<std::uint32_t>(mesh.tenant.size()))) &&
            writer.Write(mesh.tenant) &&
            writer.Write(LittleEndian(static_cast<std::uint64_t>(header.size()))) &&
            writer.Write(header) &&
            writer.Write(LittleEndian(static_cast<std::uint64_t>(mesh.mesh_bytes.size()))) &&
            writer.Write(mesh.mesh_bytes) && writer.WriteDigest();
  ok = ::fsync(fd) == 0 && ok;
  const std::string error = ErrnoText();
  ::close(fd);
  if (!ok) {
    ::unlink(path.c_str());
    spdlog::error("store: cannot write '{}': {}", EscapeForLog(path), error);
    return Status::Internal("the server cannot keep the mesh in its store (see its log)");
  }
  return path;
}

void MeshStore::Commit(const std::string& pending, const std::string& id) const {
  if (::rename(pending.c_str(), EntryPath(id).c_str()) != 0) {
    spdlog::error("store: mesh={} cannot be kept ({}): it will not come back after a restart", id,
                  ErrnoText());
    ::unlink(pending.c_str());
    return;
  }
  SyncDirectory(dir_);  // the rename is durable once the directory is synced
}

void MeshStore::Discard(const std::string& pending) const { ::unlink(pending.c_str()); }

bool MeshStore::Contains(const std::string& id) const {
  struct stat info {};
  return LooksLikeMeshId(id) && ::lstat(EntryPath(id).c_str(), &info) == 0 && S_ISREG(info.st_mode);
}

StatusOr<StoredMesh> MeshStore::Read(const std::string& id) const {
  if (!LooksLikeMeshId(id)) return Status::NotFound("no entry");
  const std::string path = EntryPath(id);
  const StatusOr<std::string> data = ReadRegularFile(path);
  if (!data.ok()) return Status::NotFound("no readable entry: " + data.status().message());
  StatusOr<StoredMesh> stored = ParseEntry(*data, key_);
  if (stored.ok() && stored->id != id) {
    stored = Status::InvalidArgument("its id '" + stored->id + "' does not match its file name");
  }
  if (!stored.ok()) {
    spdlog::error("store: the entry '{}' is corrupt: {}", EscapeForLog(path),
                  stored.status().message());
  }
  return stored;
}

StatusOr<std::string> MeshStore::PeekTenant(const std::string& id) const {
  if (!Contains(id)) return Status::NotFound("no entry");
  const int fd = ::open(EntryPath(id).c_str(), O_RDONLY | O_NONBLOCK | O_NOFOLLOW | O_CLOEXEC);
  if (fd < 0) return Status::NotFound("no readable entry");
  std::string data(kPeekBytes, '\0');
  const ssize_t n = ::pread(fd, data.data(), data.size(), 0);
  ::close(fd);
  if (n < 0) return Status::NotFound("no readable entry");
  data.resize(static_cast<std::size_t>(n));
  std::size_t offset = kMagic.size();
  std::string_view stored_id, tenant;
  if (data.size() < offset || !ReadField<std::uint32_t>(data, &offset, &stored_id) ||
      !ReadField<std::uint32_t>(data, &offset, &tenant) || stored_id != id) {
    return Status::InvalidArgument("malformed entry");
  }
  return std::string(tenant);
}

MeshStore::~MeshStore() {
  if (lock_fd_ >= 0) ::close(lock_fd_);  // releases the lock
}

Status MeshStore::Remove(const std::string& id) const {
  if (::unlink(EntryPath(id).c_str()) != 0 && errno != ENOENT) {
    spdlog::error("store: mesh={} cannot be deleted: {}", EscapeForLog(id), ErrnoText());
    return Status::Internal(
        "the server cannot delete the mesh's stored entry (see its log); it stays loaded");
  }
  SyncDirectory(dir_);
  return Status::Ok();
}

std::vector<StoredMesh> MeshStore::LoadAll() const {
  std::vector<std::string> files;
  std::error_code error;
  for (const auto& file : std::filesystem::directory_iterator(dir_, error)) {
    const std::string name = file.path().filename().string();
    if (name.size() > 5 && name[0] != '.' && name.substr(name.size() - 5) == ".mesh") {
      files.push_back(file.path().string());
    }
  }
  if (error) spdlog::error("store: cannot list '{}': {}", EscapeForLog(dir_), error.message());
  std::sort(files.begin(), files.end());
  std::vector<StoredMesh> meshes;
  for (const std::string& path : files) {
    const StatusOr<std::string> data = ReadRegularFile(path);
    if (!data.ok()) {
      spdlog::warn("store: skipping '{}': {}", EscapeForLog(path), data.status().message());
      continue;
    }
    StatusOr<StoredMesh> stored = ParseEntry(*data, key_);
    if (stored.ok() && EntryPath(stored->id) != path) {
      stored = Status::InvalidArgument("its id '" + stored->id + "' does not match its file name");
    }
    if (!stored.ok()) {
      spdlog::error("store: skipping the corrupt entry '{}': {}", EscapeForLog(path),
                    stored.status().message());
      continue;
    }
    meshes.push_back(std::move(*stored));
  }
  return meshes;
}

}  // namespace deform::service
