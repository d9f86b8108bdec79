// The mesh store (deformd --store DIR): loaded meshes kept on disk as they were uploaded (the
// LoadMesh header: name, method options, the phantom's size or the upload's format, skeleton and
// weights; and the mesh file's bytes), with their id and owner, so that a restarted server builds
// them again under the same ids for the same tenants without a client re-uploading.
//
// Layout: one file per mesh, DIR/<id>.mesh, readable and writable by the server's user only
// (0600, in a directory kept at 0700). The id is the mesh's content key (mesh_key.h), so an entry
// is immutable: whoever writes <id>.mesh writes the same mesh. A load writes a pending file
// DIR/.<id>.<random>.pending first (before parsing, so the upload's bytes need not stay in
// memory), fsyncs it, and renames it to <id>.mesh once the mesh is registered (Commit) or deletes
// it when the load fails (Discard): the rename is atomic, so a reader sees a whole entry or none,
// and a crash leaves a pending file, which Open() deletes. Unloading deletes the entry (Remove).
//
// File format (little-endian): "deformd-store v1\n", u32 length + id, u32 length + tenant,
// u64 length + serialized deform.v1.LoadMeshHeader, u64 length + mesh bytes, then the SHA-256 of
// all that. An entry whose checksum, lengths, id or tenant do not check out is corrupt: LoadAll()
// logs and skips it (the file stays for inspection); it never stops the server.
//
// Exclusive (one server): Open() takes an exclusive lock (flock) on DIR/deformd.lock, held while
// the store lives; a second server on the same directory is refused. Shared (--store-shared, the
// replicas of a cluster on one volume): every replica holds a shared lock, so an exclusive server
// and replicas never mix; pending files are deleted by Open() only once an hour old (another
// replica may be writing a younger one), and the server reads entries on demand (Read) rather
// than all at start. What sharing needs of the volume: atomic rename within the directory,
// flock, and a file that is visible to every replica once its rename returns (a local disk, or
// NFSv4 with close-to-open consistency). Open() also checks that the directory is writable (a
// read-only store is refused at start, not at the first load). Only regular files are read:
// anything else named like an entry (a FIFO, a directory, a link) is logged and skipped without
// being opened for blocking reads.
//
// Authenticity (--store-key FILE): with a key (kept outside the store) every entry is written as
// "deformd-store v2\n" with an HMAC-SHA256 under the key in place of the SHA-256, so that an entry
// whose tenant (or anything else) was edited and resealed without the key is refused at restore
// with a warning. With a key, unkeyed (v1) entries are refused too (their owner cannot be
// trusted); without one, keyed entries are. Without a key the SHA-256 is integrity only.
//
// Not encrypted: the host's disk encryption protects the files at rest (docs/operations.md, "Threat
// model"). Thread-safe (each call works on its own files).
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "core/base/status.h"
#include "deform/v1/deform.pb.h"

namespace deform::service {

struct StoredMesh {
  std::string id;
  std::string tenant;
  v1::LoadMeshHeader header;
  std::string mesh_bytes;  // the upload's mesh file; empty for a phantom
};

class MeshStore {
 public:
  // Creates `dir` (0700) if missing; otherwise it must be a directory owned by this user, and
  // its mode is set to 0700. Deletes leftover pending files. FAILED_PRECONDITION naming the
  // problem otherwise.
  // `key_file` (--store-key; empty: none): the HMAC key authenticating the entries, created
  // (32 random bytes, 0600) when missing; it must lie outside `dir` and be readable by this user
  // only.
  // `shared`: the replicas' mode (above).
  static StatusOr<std::unique_ptr<MeshStore>> Open(const std::string& dir,
                                                   const std::string& key_file = "",
                                                   bool shared = false);
  ~MeshStore();
  MeshStore(const MeshStore&) = delete;
  MeshStore& operator=(const MeshStore&) = delete;

  static constexpr const char* kLockFileName = "deformd.lock";

  // Writes `mesh` as a pending entry (durably) and returns its path. INTERNAL on an I/O error
  // (the file and the error are logged, not told to the client).
  StatusOr<std::string> WritePending(const StoredMesh& mesh) const;
  // Makes the pending entry at `pending` (WritePending's) the entry of mesh `id`, replacing an
  // entry of that id (the same content); an error is logged (the mesh then is not kept).
  void Commit(const std::string& pending, const std::string& id) const;
  // Deletes a pending entry.
  void Discard(const std::string& pending) const;
  // Deletes a mesh's entry (on unload) durably; a missing entry is not an error. INTERNAL (logged)
  // when it cannot be deleted: the caller then keeps the mesh loaded.
  Status Remove(const std::string& id) const;

  // Every readable entry, in file-name order; corrupt entries are logged and skipped.
  std::vector<StoredMesh> LoadAll() const;
  // Whether mesh `id` has an entry (a regular file; not read).
  bool Contains(const std::string& id) const;
  // The entry of mesh `id`, checked as LoadAll checks it. NOT_FOUND when there is none,
  // INVALID_ARGUMENT (logged) when it is corrupt.
  StatusOr<StoredMesh> Read(const std::string& id) const;
  // The tenant an entry names, from its first bytes, before the entry is read and checked (to
  // decide whether to read it); NOT_FOUND when there is no readable entry.
  StatusOr<std::string> PeekTenant(const std::string& id) const;

  bool shared() const { return shared_; }
  // The secret the entries are sealed with (--store-key); empty without one.
  const std::string& key() const { return key_; }

  const std::string& dir() const { return dir_; }
  std::string EntryPath(const std::string& id) const { return dir_ + "/" + id + ".mesh"; }

 private:
  MeshStore(std::string dir, int lock_fd, std::string key, bool shared)
      : dir_(std::move(dir)), lock_fd_(lock_fd), key_(std::move(key)), shared_(shared) {}
  static StatusOr<std::string> ReadOrCreateKey(const std::string& path, const std::string& dir);

  std::string dir_;
  int lock_fd_ = -1;  // holds the flock
  std::string key_;   // the HMAC key; empty: entries are checksummed only
  bool shared_;
};

}  // namespace deform::service
