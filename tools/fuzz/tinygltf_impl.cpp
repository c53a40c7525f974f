// tinygltf's implementation (and the stb image coders it uses), compiled into the fuzz build so
// that libFuzzer's coverage and the sanitizers reach inside the glTF parser. The normal build
// links Debian's libtinygltf instead. The configuration must match the header as the library's
// sources include it (no TINYGLTF_* macros), so that both sides agree on every declaration.
#define TINYGLTF_IMPLEMENTATION
#define STB_IMAGE_IMPLEMENTATION
#define STB_IMAGE_WRITE_IMPLEMENTATION
#include <tiny_gltf.h>
