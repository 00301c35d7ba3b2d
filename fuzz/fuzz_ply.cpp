// libFuzzer target: PLY loader (objects/src/ply_loader.cpp) on arbitrary bytes, then the
// local BSP of what it accepted. Run by scripts/fuzz.sh; seeds come from the loader tests.
#include "fuzz_file.hpp"
#include "fuzz_loader_check.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const auto path = dyncull::fuzz::writeInput(data, size, ".ply");
    dyncull::fuzz::checkLoaderResult(dyncull::loadPly(path), path);
    return 0;
}
