// glint — tinygltf's parser compiled into the fuzzer (instrumented, so the fuzzer sees its
// branches) in place of Debian's shared library. Images go through glint's own loader.
#define TINYGLTF_IMPLEMENTATION
#include <tiny_gltf.h>
