#include "service/access/identity.h"

#include <openssl/evp.h>

#include <cctype>
#include <fstream>
#include <sstream>
#include <vector>

namespace deform::service {
namespace {

std::vector<std::string_view> Fields(std::string_view line) {
  std::vector<std::string_view> fields;
  std::size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && (line[i] == ' ' || line[i] == '\t')) ++i;
    const std::size_t start = i;
    while (i < line.size() && line[i] != ' ' && line[i] != '\t') ++i;
    if (i > start) fields.push_back(line.substr(start, i - start));
  }
  return fields;
}

bool IsLowerHex(std::string_view text) {
  for (const char c : text) {
    if (!((c >= '0' && c <= '9') || (c >= 'a' && c <= 'f'))) return false;
  }
  return true;
}

std::string Lower(std::string_view text) {
  std::string lower(text);
  for (char& c : lower) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return lower;
}

}  // namespace

std::string Sha256Hex(std::string_view text) {
  unsigned char digest[EVP_MAX_MD_SIZE];
  unsigned int length = 0;
  EVP_Digest(text.data(), text.size(), digest, &length, EVP_sha256(), nullptr);
  static constexpr char kHex[] = "0123456789abcdef";
  std::string hex;
  hex.reserve(2 * length);
  for (unsigned int i = 0; i < length; ++i) {
    hex.push_back(kHex[digest[i] >> 4]);
    hex.push_back(kHex[digest[i] & 0xf]);
  }
  return hex;
}

bool IsValidTenantName(std::string_view name) {
  if (name.empty() || name.size() > 64) return false;
  for (const char c : name) {
    if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '.' || c == '_' || c == '-')) {
      return false;
    }
  }
  return true;
}

StatusOr<TokenTable> TokenTable::Parse(std::string_view text) {
  TokenTable table;
  int line_number = 0;
  while (!text.empty()) {
    const std::size_t newline = text.find('\n');
    std::string_view line = text.substr(0, newline);
    text = newline == std::string_view::npos ? std::string_view() : text.substr(newline + 1);
    ++line_number;
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    const std::vector<std::string_view> fields = Fields(line);
    if (fields.empty() || fields[0][0] == '#') continue;
    const std::string where = "token file line " + std::to_string(line_number);
    if (fields.size() != 3) {
      return Status::InvalidArgument(where + ": expected 3 fields (sha256 tenant role), got " +
                                     std::to_string(fields.size()));
    }
    const std::string hash = Lower(fields[0]);
    if (hash.size() != 64 || !IsLowerHex(hash)) {
      return Status::InvalidArgument(where +
                                     ": the first field is not a SHA-256 in hex (64 "
                                     "hex digits)");
    }
    if (!IsValidTenantName(fields[1])) {
      return Status::InvalidArgument(where +
                                     ": the tenant must be 1 to 64 characters of "
                                     "A-Z a-z 0-9 . _ -");
    }
    Identity identity;
    identity.tenant = std::string(fields[1]);
    if (fields[2] == "tenant") {
      identity.role = Role::kTenant;
    } else if (fields[2] == "operator") {
      identity.role = Role::kOperator;
    } else if (fields[2] == "metrics") {
      identity.role = Role::kMetrics;
    } else {
      return Status::InvalidArgument(where +
                                     ": the role must be 'tenant', 'operator' or 'metrics'");
    }
    identity.token_sha256 = hash;
    if (!table.identities_.emplace(hash, std::move(identity)).second) {
      return Status::InvalidArgument(where + ": this token hash is listed twice");
    }
  }
  return table;
}

const Identity* TokenTable::Find(const std::string& token_sha256) const {
  const auto it = identities_.find(token_sha256);
  return it == identities_.end() ? nullptr : &it->second;
}

namespace {

StatusOr<std::shared_ptr<const TokenTable>> ReadTokenFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return Status::NotFound("cannot open the token file '" + path + "'");
  std::ostringstream text;
  text << in.rdbuf();
  if (in.bad()) return Status::NotFound("cannot read the token file '" + path + "'");
  auto table = TokenTable::Parse(text.str());
  if (!table.ok()) return table.status().WithContext(path);
  return std::make_shared<const TokenTable>(std::move(*table));
}

}  // namespace

Status Authenticator::LoadTokenFile(const std::string& path) {
  DEFORM_ASSIGN_OR_RETURN(std::shared_ptr<const TokenTable> table, ReadTokenFile(path));
  MutexLock lock(&mutex_);
  path_ = path;
  table_ = std::move(table);
  return Status::Ok();
}

Status Authenticator::Reload() {
  std::string path;
  {
    MutexLock lock(&mutex_);
    if (table_ == nullptr) return Status::FailedPrecondition("no token file is in use");
    path = path_;
  }
  DEFORM_ASSIGN_OR_RETURN(std::shared_ptr<const TokenTable> table, ReadTokenFile(path));
  MutexLock lock(&mutex_);
  table_ = std::move(table);
  return Status::Ok();
}

bool Authenticator::uses_tokens() const {
  MutexLock lock(&mutex_);
  return table_ != nullptr;
}

StatusOr<Identity> Authenticator::Authenticate(std::string_view authorization) const {
  std::shared_ptr<const TokenTable> table;
  {
    MutexLock lock(&mutex_);
    table = table_;
  }
  if (table == nullptr) return Identity::Implicit();
  if (authorization.empty()) {
    return Status::Unauthenticated("no bearer token (metadata 'authorization: Bearer <token>')");
  }
  constexpr std::string_view kScheme = "bearer ";
  if (authorization.size() <= kScheme.size() ||
      Lower(authorization.substr(0, kScheme.size())) != kScheme) {
    return Status::Unauthenticated("the authorization is not a bearer token");
  }
  std::string_view token = authorization.substr(kScheme.size());
  while (!token.empty() && token.front() == ' ') token.remove_prefix(1);
  const Identity* identity = table->Find(Sha256Hex(token));
  if (identity == nullptr) return Status::Unauthenticated("unknown or revoked bearer token");
  return *identity;
}

bool Authenticator::StillValid(const Identity& caller) const {
  std::shared_ptr<const TokenTable> table;
  {
    MutexLock lock(&mutex_);
    table = table_;
  }
  if (table == nullptr) return caller.token_sha256.empty();
  const Identity* now = table->Find(caller.token_sha256);
  return now != nullptr && now->tenant == caller.tenant && now->role == caller.role;
}

const char* RoleName(Role role) {
  switch (role) {
    case Role::kTenant:
      return "tenant";
    case Role::kOperator:
      return "operator";
    case Role::kMetrics:
      return "metrics";
  }
  return "tenant";
}

}  // namespace deform::service
