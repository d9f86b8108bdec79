// Which file a GET for a URL path serves, from one directory only.
//
// ResolveStaticPath(root, target): `target` is the request target as sent
// ("/vendor/three.module.js?v=1"); the query is ignored, %XX escapes are decoded, "/" and a path
// ending in "/" mean its index.html. Refused (nullopt): a decoded path with a NUL, a backslash, a
// "." or ".." segment, an empty segment ("//"), or longer than 1 KiB; a file that does not exist or
// is not a regular file; and any path whose canonical form (symbolic links followed) is not under
// root's canonical form, so nothing outside `root` is ever served. Pure apart from reading the file
// system; thread-safe.
//
// ContentTypeFor(path): the MIME type by extension (html, js/mjs, css, json, png, svg, ico, wasm,
// txt), application/octet-stream otherwise.
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <string_view>

namespace deform::web {

std::optional<std::filesystem::path> ResolveStaticPath(const std::filesystem::path& root,
                                                       std::string_view target);

std::string_view ContentTypeFor(const std::filesystem::path& path);

}  // namespace deform::web
