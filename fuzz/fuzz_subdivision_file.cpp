// libFuzzer target: subdivision file reader (bsp/src/subdivision_file.cpp, `.dsub`). As for
// the scene cache, the 48-byte header carries a checksum, so the harness rewrites every
// input's header to be valid for its payload (magic, version, header size, payload size,
// FNV-1a, reserved 0; the source hash is kept) and fuzzes the payload parser and the
// validation behind it. Header damage is covered by tests/bsp/test_subdivision.cpp.
#include <cstdlib>
#include <cstring>
#include <vector>

#include "dyncull/bsp/subdivision_file.hpp"
#include "dyncull/objects/checksum.hpp"
#include "fuzz_file.hpp"
#include "numeric_mutator.hpp"

// Boundary values in the payload's counts and offsets (numeric_mutator.hpp, issue 19).
extern "C" std::size_t LLVMFuzzerCustomMutator(std::uint8_t* data, std::size_t size, std::size_t maxSize, unsigned seed) {
    return dyncull::fuzz::mutateBinary(data, size, maxSize, seed, dyncull::kSubdivisionFileHeaderSize);
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    using namespace dyncull;
    constexpr std::size_t kHeader = kSubdivisionFileHeaderSize;
    std::vector<std::uint8_t> bytes(kHeader, 0);
    if (size >= kHeader)
        bytes.assign(data, data + size);
    else
        bytes.insert(bytes.end(), data, data + size);
    const std::uint64_t payload = bytes.size() - kHeader, reserved = 0;
    const std::uint64_t sum = fnv1a64(bytes.data() + kHeader, payload);
    const std::uint32_t version = kSubdivisionFileVersion, headerSize = kHeader;
    std::memcpy(bytes.data(), "DYNCSUB", 8);
    std::memcpy(bytes.data() + 8, &version, 4);
    std::memcpy(bytes.data() + 12, &headerSize, 4);
    std::memcpy(bytes.data() + 24, &payload, 8);
    std::memcpy(bytes.data() + 32, &sum, 8);
    std::memcpy(bytes.data() + 40, &reserved, 8);
    const auto path = fuzz::writeInput(bytes.data(), bytes.size(), ".dsub");
    auto r = readSubdivisionFile(path);
    if (!r) {
        if (r.error().message.empty() || r.error().message.find('\n') != std::string::npos) std::abort();
        return 0;
    }
    // Accepted: the mesh is valid and every node's triangle range lies inside it.
    if (!validateMesh(r->mesh).empty() || r->subdivision.nodes.empty()) std::abort();
    const std::uint64_t triangles = r->mesh.indices.size() / 3;
    for (const SubdivisionNode& n : r->subdivision.nodes)
        if (std::uint64_t(n.firstTriangle) + n.triangleCount > triangles) std::abort();
    return 0;
}
