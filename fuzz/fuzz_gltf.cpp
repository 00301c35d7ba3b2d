// libFuzzer target: glTF loader (objects/src/gltf_loader.cpp) on arbitrary bytes, as .glb
// when the input starts with the binary magic "glTF", else as .gltf JSON; then the local
// BSP of what it accepted. Run by scripts/fuzz.sh; seeds come from the loader tests.
#include <cstring>

#include "fuzz_file.hpp"
#include "fuzz_loader_check.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const bool glb = size >= 4 && std::memcmp(data, "glTF", 4) == 0;
    const auto path = dyncull::fuzz::writeInput(data, size, glb ? ".glb" : ".gltf");
    dyncull::fuzz::checkLoaderResult(dyncull::loadGltf(path), path);
    return 0;
}
