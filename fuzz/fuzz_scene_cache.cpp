// libFuzzer target: scene cache reader (demos/scenes/src/scene_cache.cpp). The 40-byte
// header carries a checksum, so raw mutations would almost never get past it; the harness
// therefore rewrites the header of every input to be valid for its payload (magic,
// version, header size, parameter hash, payload size, FNV-1a) and fuzzes the payload
// parser, which is what must survive a hostile file with a correct checksum. The header
// checks themselves are covered by tests/demos/scene_cache_test.cpp.
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <vector>

#include "fuzz_file.hpp"
#include "numeric_mutator.hpp"
#include "scene_cache.hpp"

namespace {
constexpr std::uint64_t kHash = 0x5eed;
}

// Boundary values in the payload's counts and offsets (numeric_mutator.hpp, issue 19).
extern "C" std::size_t LLVMFuzzerCustomMutator(std::uint8_t* data, std::size_t size, std::size_t maxSize, unsigned seed) {
    return dyncull::fuzz::mutateBinary(data, size, maxSize, seed, dyncull::kSceneCacheHeaderSize);
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    using namespace dyncull;
    std::vector<std::uint8_t> bytes(kSceneCacheHeaderSize, 0);
    if (size >= kSceneCacheHeaderSize) {
        bytes.assign(data, data + size);
    } else {
        bytes.insert(bytes.end(), data, data + size);
    }
    const std::uint64_t payload = bytes.size() - kSceneCacheHeaderSize;
    const std::uint64_t sum = fnv1a64(bytes.data() + kSceneCacheHeaderSize, payload);
    const std::uint32_t version = kSceneCacheVersion, headerSize = kSceneCacheHeaderSize;
    std::memcpy(bytes.data(), "DYNCSCN", 8);
    std::memcpy(bytes.data() + 8, &version, 4);
    std::memcpy(bytes.data() + 12, &headerSize, 4);
    std::memcpy(bytes.data() + 16, &kHash, 8);
    std::memcpy(bytes.data() + 24, &payload, 8);
    std::memcpy(bytes.data() + 32, &sum, 8);
    const auto path = fuzz::writeInput(bytes.data(), bytes.size(), ".dcs");
    auto r = readSceneCache(path, kHash);
    if (!r) {
        if (r.error().message.empty() || r.error().message.find('\n') != std::string::npos) std::abort();
        return 0;
    }
    // Accepted: everything populateEngine and the traversal index must be in range.
    for (const PlacedObject& o : r->objects)
        if (o.model >= r->models.size()) std::abort();
    for (const LocalBsp& b : r->models) {
        if (!validateMesh(b.mesh).empty() || b.nodes.empty()) std::abort();
        for (const LocalBspNode& n : b.nodes)
            if (n.firstIndex + std::uint64_t(n.indexCount) > b.mesh.indices.size()) std::abort();
    }
    return 0;
}
