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

#include "dyncull/objects/checked_write.hpp"
#include "dyncull/objects/checksum.hpp"

namespace dyncull {
namespace {

static_assert(std::endian::native == std::endian::little, "subdivision files are written in host (little-endian) order");

constexpr char kMagic[8] = {'D', 'Y', 'N', 'C', 'S', 'U', 'B', '\0'};
constexpr std::size_t kNodeBytes = 6 * 4 + 5 * 4;

Error bad(const std::filesystem::path& path, const std::string& why) {
    return Error{"subdivision file " + path.string() + ": " + why};
}

class Writer {
public:
    explicit Writer(std::ofstream& f) : f_(f) {}
    void bytes(const void* p, std::size_t n) {
        f_.write(static_cast<const char*>(p), static_cast<std::streamsize>(n));
        hash_ = fnv1a64(p, n, hash_);
        size_ += n;
    }
    template <class T>
    void put(const T& v) {
        static_assert(std::is_trivially_copyable_v<T>);
        bytes(&v, sizeof(T));
    }
    template <class T>
    void array(const std::vector<T>& v) {
        put(static_cast<std::uint64_t>(v.size()));
        bytes(v.data(), v.size() * sizeof(T));
    }
    void str(const std::string& s) {
        put(static_cast<std::uint32_t>(s.size()));
        bytes(s.data(), s.size());
    }
    std::uint64_t hash() const { return hash_; }
    std::uint64_t size() const { return size_; }

private:
    std::ofstream& f_;
    std::uint64_t hash_ = kFnv1a64Seed;
    std::uint64_t size_ = 0;
};

/// Bounds-checked reader of the payload: after the first failure every read fails and
/// yields zeros, so the parser checks once per record; counts above the bytes left fail
/// before any allocation.
class Reader {
public:
    Reader(std::ifstream& f, std::uint64_t size) : f_(f), left_(size) {}
    bool bytes(void* p, std::size_t n) {
        if (fail_ || n > left_) {
            fail_ = true;
            std::memset(p, 0, n);
            return false;
        }
        f_.read(static_cast<char*>(p), static_cast<std::streamsize>(n));
        if (!f_) {
            fail_ = true;
            return false;
        }
        left_ -= n;
        return true;
    }
    template <class T>
    T get() {
        T v{};
        bytes(&v, sizeof(T));
        return v;
    }
    template <class T>
    bool array(std::vector<T>& v) {
        const auto n = get<std::uint64_t>();
        if (fail_ || n > left_ / sizeof(T)) return fail_ = true, false;
        v.resize(static_cast<std::size_t>(n));
        return bytes(v.data(), v.size() * sizeof(T));
    }
    bool str(std::string& s, std::uint32_t maxLength) {
        const auto n = get<std::uint32_t>();
        if (fail_ || n > left_ || n > maxLength) return fail_ = true, false;
        s.resize(n);
        return bytes(s.data(), n);
    }
    bool failed() const { return fail_; }
    std::uint64_t left() const { return left_; }

private:
    std::ifstream& f_;
    std::uint64_t left_;
    bool fail_ = false;
};

}  // namespace

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
        Writer w(f);
        w.str(m.source);
        const SubdivisionParams& p = m.params;
        w.put(static_cast<std::uint8_t>(p.method));
        w.put(p.maxLeafTriangles);
        w.put(p.maxDepth);
        w.put(p.exactBelow);
        w.put(p.sahBins);
        w.put(p.planeMove);
        w.put(p.pullUpWidths);
        w.put(p.collapseTo);
        w.str(m.mesh.name);
        w.array(m.mesh.positions);
        w.array(m.mesh.normals);
        w.array(m.mesh.indices);
        w.put(static_cast<std::uint64_t>(m.subdivision.nodes.size()));
        for (const SubdivisionNode& n : m.subdivision.nodes) {
            w.put(n.box.min);
            w.put(n.box.max);
            w.put(n.firstChild);
            w.put(n.childCount);
            w.put(n.firstTriangle);
            w.put(n.triangleCount);
            w.put(n.depth);
        }
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
    {
        std::vector<char> chunk(1 << 20);
        std::uint64_t hash = kFnv1a64Seed, left = payload;
        while (left > 0) {
            const auto n = static_cast<std::size_t>(std::min<std::uint64_t>(left, chunk.size()));
            f.read(chunk.data(), static_cast<std::streamsize>(n));
            if (!f) return bad(path, "read failed");
            hash = fnv1a64(chunk.data(), n, hash);
            left -= n;
        }
        if (hash != sum) return bad(path, "checksum mismatch (corrupt)");
    }
    f.seekg(static_cast<std::streamoff>(kSubdivisionFileHeaderSize));

    Reader r(f, payload);
    SubdividedModel m;
    m.sourceHash = sourceHash;
    if (!r.str(m.source, 4096)) return bad(path, "truncated source name");
    SubdivisionParams& p = m.params;
    const auto method = r.get<std::uint8_t>();
    if (method > static_cast<std::uint8_t>(SubdivisionMethod::Grid)) return bad(path, "unknown method " + std::to_string(method));
    p.method = static_cast<SubdivisionMethod>(method);
    p.maxLeafTriangles = r.get<std::uint32_t>();
    p.maxDepth = r.get<std::uint32_t>();
    p.exactBelow = r.get<std::uint32_t>();
    p.sahBins = r.get<std::uint32_t>();
    p.planeMove = r.get<float>();
    p.pullUpWidths = r.get<float>();
    p.collapseTo = r.get<std::uint32_t>();
    if (r.failed()) return bad(path, "truncated parameters");
    if (Status s = validateSubdivisionParams(p); !s) return bad(path, s.message());
    if (!r.str(m.mesh.name, 4096) || !r.array(m.mesh.positions) || !r.array(m.mesh.normals) || !r.array(m.mesh.indices))
        return bad(path, "truncated mesh");
    if (std::string why = validateMesh(m.mesh); !why.empty()) return bad(path, why);
    if (std::string why = validateNormals(m.mesh); !why.empty()) return bad(path, why);
    const auto nodes = r.get<std::uint64_t>();
    if (r.failed() || nodes == 0 || nodes > r.left() / kNodeBytes) return bad(path, "node count out of range");
    Subdivision& sub = m.subdivision;
    sub.method = p.method;
    sub.nodes.resize(static_cast<std::size_t>(nodes));
    for (SubdivisionNode& n : sub.nodes) {
        n.box.min = r.get<glm::vec3>();
        n.box.max = r.get<glm::vec3>();
        n.firstChild = r.get<std::uint32_t>();
        n.childCount = r.get<std::uint32_t>();
        n.firstTriangle = r.get<std::uint32_t>();
        n.triangleCount = r.get<std::uint32_t>();
        n.depth = r.get<std::uint32_t>();
    }
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
