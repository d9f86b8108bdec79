#include "service/registry/mesh_key.h"

#include <google/protobuf/io/coded_stream.h>
#include <google/protobuf/io/zero_copy_stream_impl_lite.h>
#include <openssl/evp.h>
#include <openssl/hmac.h>
#include <openssl/rand.h>

#include <cstdint>
#include <cstdlib>
#include <memory>
#include <string_view>

namespace deform::service {
namespace {

constexpr std::string_view kDomain = "deformd mesh key v1";
constexpr std::string_view kDerivation = "deformd mesh keys";
constexpr std::size_t kSecretBytes = 32;
constexpr std::size_t kKeyBytes = 16;

std::string Hmac(const std::string& key, std::string_view data) {
  unsigned char digest[EVP_MAX_MD_SIZE];
  unsigned int length = 0;
  HMAC(EVP_sha256(), key.data(), static_cast<int>(key.size()),
       reinterpret_cast<const unsigned char*>(data.data()), data.size(), digest, &length);
  return std::string(reinterpret_cast<const char*>(digest), length);
}

// The header as the key sees it: deterministic bytes, the name left out.
std::string CanonicalHeader(const v1::LoadMeshHeader& header) {
  v1::LoadMeshHeader copy = header;
  copy.clear_name();
  std::string bytes;
  {
    google::protobuf::io::StringOutputStream output(&bytes);
    google::protobuf::io::CodedOutputStream coded(&output);
    coded.SetSerializationDeterministic(true);
    copy.SerializeToCodedStream(&coded);
  }
  return bytes;
}

class HmacStream {
 public:
  explicit HmacStream(const std::string& key)
      : context_(EVP_MD_CTX_new()),
        pkey_(EVP_PKEY_new_raw_private_key(EVP_PKEY_HMAC, nullptr,
                                           reinterpret_cast<const unsigned char*>(key.data()),
                                           key.size())) {
    EVP_DigestSignInit(context_, nullptr, EVP_sha256(), nullptr, pkey_);
  }
  ~HmacStream() {
    EVP_MD_CTX_free(context_);
    EVP_PKEY_free(pkey_);
  }
  HmacStream(const HmacStream&) = delete;
  HmacStream& operator=(const HmacStream&) = delete;

  // A length-prefixed part.
  void AddPart(std::string_view bytes) {
    unsigned char length[8];
    for (int i = 0; i < 8; ++i) {
      length[i] = static_cast<unsigned char>((std::uint64_t{bytes.size()} >> (8 * i)) & 0xff);
    }
    EVP_DigestSignUpdate(context_, length, sizeof length);
    EVP_DigestSignUpdate(context_, bytes.data(), bytes.size());
  }
  std::string Finish() {
    unsigned char digest[EVP_MAX_MD_SIZE];
    std::size_t length = sizeof digest;
    if (EVP_DigestSignFinal(context_, digest, &length) != 1) std::abort();  // cannot fail on HMAC
    return std::string(reinterpret_cast<const char*>(digest), length);
  }

 private:
  EVP_MD_CTX* context_;
  EVP_PKEY* pkey_;
};

}  // namespace

MeshKeys::MeshKeys() {
  std::string secret(kSecretBytes, '\0');
  if (RAND_bytes(reinterpret_cast<unsigned char*>(secret.data()), kSecretBytes) != 1) {
    std::abort();  // as NewMeshId: a key from a weak source would be worse than none
  }
  derived_ = Hmac(secret, kDerivation);
}

MeshKeys::MeshKeys(const std::string& secret) : derived_(Hmac(secret, kDerivation)) {}

std::string MeshKeys::KeyOf(const std::string& tenant, const v1::LoadMeshHeader& header,
                            const std::string& mesh_bytes) const {
  HmacStream hmac(derived_);
  hmac.AddPart(kDomain);
  hmac.AddPart(tenant);
  hmac.AddPart(CanonicalHeader(header));
  hmac.AddPart(mesh_bytes);
  const std::string digest = hmac.Finish();
  static constexpr char kHex[] = "0123456789abcdef";
  std::string key = "mesh-";
  for (std::size_t i = 0; i < kKeyBytes; ++i) {
    const auto byte = static_cast<unsigned char>(digest[i]);
    key.push_back(kHex[byte >> 4]);
    key.push_back(kHex[byte & 0xf]);
  }
  return key;
}

}  // namespace deform::service
