// The one translation unit that compiles tinygltf's implementation, configured as tiny_gltf.h says.
// tinygltf 2.7 uses std::ofstream in its file writers even with TINYGLTF_NO_FS.
#include <fstream>

#define TINYGLTF_IMPLEMENTATION
#include "tiny_gltf.h"
