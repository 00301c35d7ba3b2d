// libFuzzer target: OBJ loader (objects/src/obj_loader.cpp) on arbitrary bytes, then the
// local BSP of what it accepted. Run by scripts/fuzz.sh; seeds come from
// fuzz_make_seeds and the loader tests, tokens from fuzz/obj.dict. The custom mutator
// replaces numbers (vertex indices, coordinates) with boundary values
// (numeric_mutator.hpp, issue 19).
#include "fuzz_file.hpp"
#include "fuzz_loader_check.hpp"
#include "numeric_mutator.hpp"

extern "C" std::size_t LLVMFuzzerCustomMutator(std::uint8_t* data, std::size_t size, std::size_t maxSize, unsigned seed) {
    return dyncull::fuzz::mutateText(data, size, maxSize, seed, false);
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const auto path = dyncull::fuzz::writeInput(data, size, ".obj");
    dyncull::fuzz::checkLoaderResult(dyncull::loadObj(path), path);
    return 0;
}
