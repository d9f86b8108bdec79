// tinygltf (Debian's libtinygltf-dev 2.7, header-only), configured the one way the io layer uses
// it: no image decoding or encoding (no stb_image), no external images, and no file reading
// compiled in (TINYGLTF_NO_FS: tinygltf has no default file callbacks, and the importer supplies
// ones that refuse; only its file *writers*, WriteGltfSceneToFile, still compile, and nothing
// calls them). Include only this header, never <tiny_gltf.h> directly, so that every translation
// unit sees the same configuration; tiny_gltf_impl.cc compiles the implementation. Private to the
// io layer: no public header mentions tinygltf.
#pragma once

#define TINYGLTF_NO_STB_IMAGE
#define TINYGLTF_NO_STB_IMAGE_WRITE
#define TINYGLTF_NO_EXTERNAL_IMAGE
#define TINYGLTF_NO_FS
#define TINYGLTF_NO_INCLUDE_STB_IMAGE
#define TINYGLTF_NO_INCLUDE_STB_IMAGE_WRITE

// /usr/include is a system include folder, so tinygltf's own warnings stay silent here.
#include <tiny_gltf.h>
