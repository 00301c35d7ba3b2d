// libFuzzer target: glTF loader (objects/src/gltf_loader.cpp) on arbitrary bytes, as .glb
// when the input starts with the binary magic "glTF", else as .gltf JSON; then the local
// BSP of what it accepted. Run by scripts/fuzz.sh with fuzz/gltf.dict; seeds come from
// fuzz_make_seeds and the loader tests.
//
// Structure-aware (issue 19): the custom mutator replaces JSON numbers with boundary values
// and wraps values in deep brackets (numeric_mutator.hpp). A .glb's JSON chunk is mutated
// on its own and the container re-framed (chunk length, padding, total length), so the
// mutation reaches the JSON instead of breaking the "Invalid glTF binary" checks.
#include <algorithm>
#include <cstring>
#include <vector>

#include "fuzz_file.hpp"
#include "fuzz_loader_check.hpp"
#include "numeric_mutator.hpp"

namespace {

constexpr std::size_t kGlbHeader = 12, kChunkHeader = 8;

bool isGlb(const std::uint8_t* data, std::size_t size) { return size >= 4 && std::memcmp(data, "glTF", 4) == 0; }

std::uint32_t load32(const std::uint8_t* p) {
    std::uint32_t v;
    std::memcpy(&v, p, 4);  // GLB is little-endian, as is every host we build for
    return v;
}

void store32(std::uint8_t* p, std::uint32_t v) { std::memcpy(p, &v, 4); }

// Mutates the JSON chunk of a .glb and rebuilds header and chunk framing around it; the
// bytes after the JSON chunk (the BIN chunk) are kept. 0 when the input is not framed
// well enough to find its JSON chunk.
std::size_t mutateGlb(std::uint8_t* data, std::size_t size, std::size_t maxSize, unsigned seed) {
    if (size < kGlbHeader + kChunkHeader) return 0;
    const std::size_t jsonLength = std::min<std::size_t>(load32(data + 12), size - kGlbHeader - kChunkHeader);
    const std::size_t jsonBegin = kGlbHeader + kChunkHeader;
    const std::size_t restBegin = jsonBegin + jsonLength;
    const std::size_t rest = size - restBegin;
    if (maxSize < jsonBegin + rest) return 0;
    // Room for the mutated JSON, a multiple of 4 so that padding it always fits.
    const std::size_t capacity = (maxSize - jsonBegin - rest) / 4 * 4;
    if (capacity < jsonLength) return 0;
    std::vector<std::uint8_t> json(capacity);
    std::memcpy(json.data(), data + jsonBegin, jsonLength);
    std::size_t n = dyncull::fuzz::mutateText(json.data(), jsonLength, capacity, seed, true);
    while (n % 4) json[n++] = ' ';  // the spec pads the JSON chunk with spaces
    std::memmove(data + jsonBegin + n, data + restBegin, rest);
    std::memcpy(data + jsonBegin, json.data(), n);
    const std::size_t total = jsonBegin + n + rest;
    store32(data + 4, 2);
    store32(data + 8, static_cast<std::uint32_t>(total));
    store32(data + 12, static_cast<std::uint32_t>(n));
    std::memcpy(data + 16, "JSON", 4);
    return total;
}

}  // namespace

extern "C" std::size_t LLVMFuzzerCustomMutator(std::uint8_t* data, std::size_t size, std::size_t maxSize, unsigned seed) {
    // One in eight .glb mutations goes to the raw bytes so the container parser is fuzzed too.
    if (isGlb(data, size) && seed % 8 != 0 && !dyncull::fuzz::plainMutation())
        if (const std::size_t n = mutateGlb(data, size, maxSize, seed / 8)) return n;
    return dyncull::fuzz::mutateText(data, size, maxSize, seed, true);
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const bool glb = isGlb(data, size);
    const auto path = dyncull::fuzz::writeInput(data, size, glb ? ".glb" : ".gltf");
    dyncull::fuzz::checkLoaderResult(dyncull::loadGltf(path), path);
    return 0;
}
