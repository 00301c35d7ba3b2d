// libFuzzer target: PLY loader (objects/src/ply_loader.cpp) on arbitrary bytes, then the
// local BSP of what it accepted. Run by scripts/fuzz.sh; seeds come from
// fuzz_make_seeds and the loader tests, tokens from fuzz/ply.dict. The custom mutator
// replaces numbers (header counts, property values, list lengths) with boundary values
// (numeric_mutator.hpp, issue 19).
#include "fuzz_file.hpp"
#include "fuzz_loader_check.hpp"
#include "numeric_mutator.hpp"

extern "C" std::size_t LLVMFuzzerCustomMutator(std::uint8_t* data, std::size_t size, std::size_t maxSize, unsigned seed) {
    return dyncull::fuzz::mutateText(data, size, maxSize, seed, false);
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const auto path = dyncull::fuzz::writeInput(data, size, ".ply");
    dyncull::fuzz::checkLoaderResult(dyncull::loadPly(path), path);
    return 0;
}
