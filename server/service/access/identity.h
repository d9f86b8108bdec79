// Who is calling: bearer tokens from a token file, mapped to a tenant and a role.
//
// Token file (deformd --token-file), one token per line, fields separated by spaces or tabs:
//
//     # comment lines and blank lines are ignored
//     <sha256 of the token, 64 hex digits>  <tenant>  <role>
//
// tenant: 1 to 64 characters of [A-Za-z0-9._-]; role: `tenant` (sees and changes only its own
// tenant's meshes), `operator` (sees and changes every tenant's meshes; each access to another
// tenant's mesh leaves an audit line, action=cross_tenant) or `metrics` (scrapes the metrics port
// and nothing else: every call and HTTP API request is PERMISSION_DENIED). The file holds hashes
// only, so reading it does not reveal a token (`printf %s "$TOKEN" | sha256sum`). The same hash
// twice, a malformed line or an unknown role is an error naming the line.
//
// Authenticator::Authenticate maps the value of an "authorization" header ("Bearer <token>") to
// an Identity; it knows nothing of gRPC, so any transport (the gRPC port today, an HTTP or
// WebSocket port tomorrow) uses the same check. Without a token file every caller is the single
// implicit tenant (Identity::Implicit()), what the server did before tokens existed.
//
// Thread safety: Authenticator is thread-safe; Reload() swaps the table atomically, so calls see
// either the old tokens or the new ones.
#pragma once

#include <cstddef>
#include <map>
#include <memory>
#include <string>
#include <string_view>

#include "core/base/status.h"
#include "service/base/annotated_mutex.h"
#include "service/base/thread_annotations.h"

namespace deform::service {

enum class Role { kTenant, kOperator, kMetrics };

// The token file's name of `role` ("tenant", "operator", "metrics").
const char* RoleName(Role role);

struct Identity {
  std::string tenant;
  Role role = Role::kTenant;
  // The SHA-256 of the token the caller presented; empty without a token file. A stream keeps
  // it, so that a reload can tell whether its token still stands (Authenticator::StillValid).
  std::string token_sha256;

  // The tenant every caller is when the server has no token file.
  static Identity Implicit() { return {"default", Role::kTenant, ""}; }
  // May this caller see (and stream, unload) a mesh owned by `owner`?
  bool CanAccess(const std::string& owner) const {
    return role == Role::kOperator || (role == Role::kTenant && owner == tenant);
  }
};

// A parsed token file: hash -> identity. Immutable.
class TokenTable {
 public:
  // INVALID_ARGUMENT naming the line for a malformed file.
  static StatusOr<TokenTable> Parse(std::string_view text);
  // The identity of the token whose SHA-256 (lower-case hex) is `token_sha256`, or null.
  const Identity* Find(const std::string& token_sha256) const;
  std::size_t size() const { return identities_.size(); }

 private:
  std::map<std::string, Identity> identities_;
};

// Lower-case hex SHA-256 of `text`.
std::string Sha256Hex(std::string_view text);

// True for a valid tenant name (above).
bool IsValidTenantName(std::string_view name);

class Authenticator {
 public:
  // No token file: every caller is Identity::Implicit().
  Authenticator() = default;

  // Reads the token file at `path` and uses it from now on (also for Reload()). NOT_FOUND or
  // INVALID_ARGUMENT (naming the line) leave the authenticator as it was.
  Status LoadTokenFile(const std::string& path) DEFORM_EXCLUDES(mutex_);
  // Reads the same file again (deformd's SIGHUP). On error the old tokens stay in force.
  // FAILED_PRECONDITION when no token file was loaded.
  Status Reload() DEFORM_EXCLUDES(mutex_);
  // Whether a token file is in force.
  bool uses_tokens() const DEFORM_EXCLUDES(mutex_);

  // The caller presenting `authorization` (the header's value, "Bearer <token>"; the scheme is
  // case-insensitive). UNAUTHENTICATED without a header, with another scheme, or with an unknown
  // token (the message never echoes the token). Without a token file: Identity::Implicit().
  StatusOr<Identity> Authenticate(std::string_view authorization) const DEFORM_EXCLUDES(mutex_);
  // Whether `caller` (from Authenticate) would still be the same identity: its token is still
  // listed with the same tenant and role. Always true without a token file.
  bool StillValid(const Identity& caller) const DEFORM_EXCLUDES(mutex_);

 private:
  mutable Mutex mutex_;
  std::string path_ DEFORM_GUARDED_BY(mutex_);
  std::shared_ptr<const TokenTable> table_ DEFORM_GUARDED_BY(mutex_);  // null: no token file
};

}  // namespace deform::service
