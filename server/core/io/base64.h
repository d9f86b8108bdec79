// Base64 (RFC 4648, section 4: the standard alphabet, '=' padding, no line breaks), as glTF's
// data URIs embed buffers.
#pragma once

#include <string>
#include <string_view>

namespace deform {

// The base64 text of `bytes`: 4 characters per 3 bytes, the last group padded with '='.
std::string Base64Encode(std::string_view bytes);

}  // namespace deform
