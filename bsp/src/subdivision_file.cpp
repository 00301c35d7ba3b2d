// Subdivision file reader and writer; format in subdivision_file.hpp. Both stream (no
// second copy of a 13M-triangle mesh in memory); the reader checksums the whole payload
// in a first pass so corruption is reported as such before any content is parsed.
#include "dyncull/bsp/subdivision_file.hpp"

#include <bit>
#include <cmath>
#include <cstring>
#include <fstream>
#include <type_traits>
#include <vector>

#include "dyncull/objects/binary_file.hpp"
#include "dyncull/objects/checked_write.hpp"

namespace dyncull {
namespace {

constexpr char kMagic[8] = {'D', 'Y', 'N', 'C', 'S', 'U', 'B', '\0'};
Error bad(const std::filesystem::path& path, const std::string& why) {
    return Error{"subdivision file " + path.string() + ": " + why};
}

}  // namespace

void writeSubdivisionParams(BinaryWriter& w, const SubdivisionParams& p) {
    w.put(static_cast<std::uint8_t>(p.method));
    w.put(p.maxLeafTriangles);
    w.put(p.maxDepth);
    w.put(p.exactBelow);
    w.put(p.sahBins);
    w.put(p.planeMove);
    w.put(p.pullUpWidths);
    w.put(p.collapseTo);
}

std::string readSubdivisionParams(BinaryReader& r, SubdivisionParams& p) {
    const auto method = r.get<std::uint8_t>();
    if (method > static_cast<std::uint8_t>(SubdivisionMethod::Grid)) return "unknown method " + std::to_string(method);
    p.method = static_cast<SubdivisionMethod>(method);
    p.maxLeafTriangles = r.get<std::uint32_t>();
    p.maxDepth = r.get<std::uint32_t>();
    p.exactBelow = r.get<std::uint32_t>();
    p.sahBins = r.get<std::uint32_t>();
    p.planeMove = r.get<float>();
    p.pullUpWidths = r.get<float>();
    p.collapseTo = r.get<std::uint32_t>();
    if (r.failed()) return "truncated parameters";
    if (Status s = validateSubdivisionParams(p); !s) return s.message();
    return {};
}

void writeSubdivisionNode(BinaryWriter& w, const SubdivisionNode& n) {
    w.put(n.box.min);
    w.put(n.box.max);
    w.put(n.firstChild);
    w.put(n.childCount);
    w.put(n.firstTriangle);
    w.put(n.triangleCount);
    w.put(n.depth);
}

SubdivisionNode readSubdivisionNode(BinaryReader& r) {
    SubdivisionNode n;
    n.box.min = r.get<glm::vec3>();
    n.box.max = r.get<glm::vec3>();
    n.firstChild = r.get<std::uint32_t>();
    n.childCount = r.get<std::uint32_t>();
    n.firstTriangle = r.get<std::uint32_t>();
    n.triangleCount = r.get<std::uint32_t>();
    n.depth = r.get<std::uint32_t>();
    return n;
}

Status writeSubdivisionFile(const std::filesystem::path& path, const SubdividedModel& m) {
    if (!m.subdivision.triangles.empty())
        return Error{"subdivision file " + path.string() + ": triangle order not applied to the mesh"};
    std::filesystem::path tmp = path;
    tmp += ".tmp";
    std::uint64_t hash = 0, payload = 0;
    {
        std::ofstream f(tmp, std::ios::binary | std::ios::trunc);
        if (!f) return bad(tmp, "cannot write");
        const char zeros[kSubdivisionFileHeaderSize] = {};
        f.write(zeros, sizeof zeros);
        BinaryWriter w(f);
        w.str<std::uint32_t>(m.source);
        writeSubdivisionParams(w, m.params);
        w.str<std::uint32_t>(m.mesh.name);
        w.array<std::uint64_t>(m.mesh.positions);
        w.array<std::uint64_t>(m.mesh.normals);
        w.array<std::uint64_t>(m.mesh.indices);
        w.put(static_cast<std::uint64_t>(m.subdivision.nodes.size()));
        for (const SubdivisionNode& n : m.subdivision.nodes) writeSubdivisionNode(w, n);
        w.put(m.subdivision.stats.buildMs);
        w.put(static_cast<std::uint64_t>(m.subdivision.stats.workBytes));
        hash = w.hash();
        payload = w.size();
        const std::uint32_t version = kSubdivisionFileVersion, headerSize = kSubdivisionFileHeaderSize;
        const std::uint64_t reserved = 0;
        char h[kSubdivisionFileHeaderSize];
        std::memcpy(h, kMagic, 8);
        std::memcpy(h + 8, &version, 4);
        std::memcpy(h + 12, &headerSize, 4);
        std::memcpy(h + 16, &m.sourceHash, 8);
        std::memcpy(h + 24, &payload, 8);
        std::memcpy(h + 32, &hash, 8);
        std::memcpy(h + 40, &reserved, 8);
        f.seekp(0);
        f.write(h, sizeof h);
        if (!f) return bad(tmp, "write failed (disk full?)");
        // The close flushes the last buffer: a full disk may show only here.
        if (Status s = closeChecked(f, tmp); !s) return Error{"subdivision file " + s.message()};
    }
    std::error_code ec;
    std::filesystem::rename(tmp, path, ec);
    if (ec) return bad(path, "cannot rename into place: " + ec.message());
    return {};
}

Expected<SubdividedModel> readSubdivisionFile(const std::filesystem::path& path) {
    std::ifstream f(path, std::ios::binary | std::ios::ate);
    if (!f) return bad(path, "cannot open");
    const std::streamoff end = f.tellg();
    if (end < 0) return bad(path, "cannot size");
    const auto size = static_cast<std::uint64_t>(end);
    if (size < kSubdivisionFileHeaderSize) return bad(path, "truncated header (" + std::to_string(size) + " bytes)");
    char h[kSubdivisionFileHeaderSize];
    f.seekg(0);
    f.read(h, sizeof h);
    if (!f) return bad(path, "cannot read header");
    if (std::memcmp(h, kMagic, 8) != 0) return bad(path, "bad magic (not a dyncull subdivision file)");
    std::uint32_t version = 0, headerSize = 0;
    std::uint64_t sourceHash = 0, payload = 0, sum = 0, reserved = 0;
    std::memcpy(&version, h + 8, 4);
    std::memcpy(&headerSize, h + 12, 4);
    std::memcpy(&sourceHash, h + 16, 8);
    std::memcpy(&payload, h + 24, 8);
    std::memcpy(&sum, h + 32, 8);
    std::memcpy(&reserved, h + 40, 8);
    if (version != kSubdivisionFileVersion)
        return bad(path, "format version " + std::to_string(version) + ", expected " + std::to_string(kSubdivisionFileVersion));
    if (headerSize != kSubdivisionFileHeaderSize || reserved != 0) return bad(path, "bad header");
    if (payload != size - kSubdivisionFileHeaderSize)
        return bad(path, "truncated or padded: header says " + std::to_string(payload) + " payload bytes, file has " +
                             std::to_string(size - kSubdivisionFileHeaderSize));
    if (std::string why = checkPayload(f, payload, sum); !why.empty()) return bad(path, why);
    f.seekg(static_cast<std::streamoff>(kSubdivisionFileHeaderSize));

    BinaryReader r(f, payload);
    SubdividedModel m;
    m.sourceHash = sourceHash;
    if (!r.str<std::uint32_t>(m.source, 4096)) return bad(path, "truncated source name");
    SubdivisionParams& p = m.params;
    if (std::string why = readSubdivisionParams(r, p); !why.empty()) return bad(path, why);
    if (!r.str<std::uint32_t>(m.mesh.name, 4096) || !r.array<std::uint64_t>(m.mesh.positions) || !r.array<std::uint64_t>(m.mesh.normals) || !r.array<std::uint64_t>(m.mesh.indices))
        return bad(path, "truncated mesh");
    if (std::string why = validateMesh(m.mesh); !why.empty()) return bad(path, why);
    if (std::string why = validateNormals(m.mesh); !why.empty()) return bad(path, why);
    const auto nodes = r.get<std::uint64_t>();
    if (r.failed() || nodes == 0 || nodes > r.left() / kSubdivisionNodeBytes) return bad(path, "node count out of range");
    Subdivision& sub = m.subdivision;
    sub.method = p.method;
    sub.nodes.resize(static_cast<std::size_t>(nodes));
    for (SubdivisionNode& n : sub.nodes) n = readSubdivisionNode(r);
    sub.stats.buildMs = r.get<double>();
    sub.stats.workBytes = static_cast<std::size_t>(r.get<std::uint64_t>());
    if (r.failed()) return bad(path, "truncated tree");
    if (!std::isfinite(sub.stats.buildMs) || sub.stats.buildMs < 0.0) return bad(path, "build time is not a finite duration");
    if (r.left() != 0) return bad(path, std::to_string(r.left()) + " trailing payload bytes");
    if (std::string why = validateSubdivision(m.mesh, sub, p.maxLeafTriangles, p.maxDepth); !why.empty())
        return bad(path, why);
    recountSubdivisionStats(sub, p.maxLeafTriangles);  // counts are recomputed, never read
    return m;
}

}  // namespace dyncull
