// The geometry file of a streamed model: chunk encoding and the leaf reader. A chunk is
// checked before it is decoded (checksum, then every count against the bytes present),
// so a corrupt or hostile file is an error naming the leaf, never a crash.
#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <cstring>

#include "dyncull/objects/checksum.hpp"
#include "dyncull/streaming/compact_leaf.hpp"
#include "geometry_chunk.hpp"

namespace dyncull {
namespace detail {

std::string encodeChunk(const Mesh& g, std::vector<unsigned char>& out) {
    const std::size_t v = g.positions.size(), idx = g.indices.size();
    if (v == 0 || idx == 0 || idx % 3 != 0) return "a leaf needs vertices and whole triangles";
    if (g.normals.size() != v) return "a leaf needs one normal per vertex";
    if (v > 0xFFFFFFFFu || idx / 3 > 0xFFFFFFFFu) return "a leaf with more than 2^32 - 1 vertices or triangles";
    const std::uint32_t indexBytes = v <= 0x10000 ? 2 : 4;  // 16-bit indices where they reach
    // Each term is below 2^32 * 12 and there are three: no overflow in 64 bits.
    const std::uint64_t raw = kChunkHeaderBytes + std::uint64_t(v) * 24 + std::uint64_t(idx) * indexBytes;
    const std::uint64_t bytes = (raw + 3) / 4 * 4;
    if (bytes > kMaxLeafChunkBytes) return "a leaf chunk of " + std::to_string(bytes) + " bytes (the limit is 256 MiB)";
    out.assign(static_cast<std::size_t>(bytes), 0);
    unsigned char* p = out.data();
    const std::uint32_t head[4] = {static_cast<std::uint32_t>(v), static_cast<std::uint32_t>(idx / 3), indexBytes, 0};
    std::memcpy(p, head, sizeof head);
    p += sizeof head;
    std::memcpy(p, g.positions.data(), v * sizeof(glm::vec3));
    p += v * sizeof(glm::vec3);
    std::memcpy(p, g.normals.data(), v * sizeof(glm::vec3));
    p += v * sizeof(glm::vec3);
    for (std::uint32_t i : g.indices) {
        if (i >= v) return "a leaf index out of range";
        if (indexBytes == 2) {
            const auto s = static_cast<std::uint16_t>(i);
            std::memcpy(p, &s, 2);
        } else {
            std::memcpy(p, &i, 4);
        }
        p += indexBytes;
    }
    return {};
}

void encodeGeometryHeader(std::uint64_t geometryId, std::uint64_t fileBytes, unsigned char out[kStreamedHeaderSize]) {
    std::memset(out, 0, kStreamedHeaderSize);
    const std::uint32_t version = kStreamedModelVersion, headerSize = kStreamedHeaderSize;
    std::memcpy(out, kGeometryMagic, 8);
    std::memcpy(out + 8, &version, 4);
    std::memcpy(out + 12, &headerSize, 4);
    std::memcpy(out + 16, &geometryId, 8);
    std::memcpy(out + 24, &fileBytes, 8);
}

bool writeAllAt(int fd, const void* bytes, std::size_t size, std::uint64_t offset) {
    const auto* p = static_cast<const unsigned char*>(bytes);
    while (size > 0) {
        const ssize_t n = ::pwrite(fd, p, size, static_cast<off_t>(offset));
        if (n < 0 && errno == EINTR) continue;
        if (n <= 0) return false;
        p += n;
        size -= static_cast<std::size_t>(n);
        offset += static_cast<std::uint64_t>(n);
    }
    return true;
}

bool readAllAt(int fd, void* bytes, std::size_t size, std::uint64_t offset) {
    auto* p = static_cast<unsigned char*>(bytes);
    while (size > 0) {
        const ssize_t n = ::pread(fd, p, size, static_cast<off_t>(offset));
        if (n < 0 && errno == EINTR) continue;
        if (n <= 0) return false;
        p += n;
        size -= static_cast<std::size_t>(n);
        offset += static_cast<std::uint64_t>(n);
    }
    return true;
}

}  // namespace detail

std::size_t leafBytes(const Mesh& leaf) {
    return (leaf.positions.size() + leaf.normals.size()) * sizeof(glm::vec3) + leaf.indices.size() * sizeof(std::uint32_t);
}

std::size_t leafBytes(const StreamedLeaf& leaf) {
    // A position and a normal per vertex, three 32-bit indices per triangle, as read.
    return std::size_t{leaf.vertexCount} * 2 * sizeof(glm::vec3) + std::size_t{leaf.triangleCount} * 3 * sizeof(std::uint32_t);
}

struct GeometryFile::State {
    std::filesystem::path path;
    std::vector<StreamedLeaf> leaves;
    int fd = -1;
    ~State() {
        if (fd >= 0) ::close(fd);
    }
};

GeometryFile::GeometryFile(std::unique_ptr<State> s) : s_(std::move(s)) {}
GeometryFile::GeometryFile(GeometryFile&&) noexcept = default;
GeometryFile& GeometryFile::operator=(GeometryFile&&) noexcept = default;
GeometryFile::~GeometryFile() = default;

std::uint32_t GeometryFile::leafCount() const { return static_cast<std::uint32_t>(s_->leaves.size()); }

Expected<GeometryFile> GeometryFile::open(const StreamedModel& model) {
    auto s = std::make_unique<State>();
    s->path = model.geometryPath;
    s->leaves = model.leaves;
    s->fd = ::open(s->path.c_str(), O_RDONLY | O_CLOEXEC);
    if (s->fd < 0) return Error{"geometry file " + s->path.string() + ": cannot open: " + std::strerror(errno), ErrorCode::BadFile};
    return GeometryFile(std::move(s));
}

Status GeometryFile::read(std::uint32_t leafIndex, Mesh& out, std::vector<unsigned char>& scratch) const {
    const State& s = *s_;
    if (leafIndex >= s.leaves.size())
        return Error{"geometry file " + s.path.string() + ": no leaf " + std::to_string(leafIndex), ErrorCode::BadArgument};
    const StreamedLeaf& leaf = s.leaves[leafIndex];
    const auto bad = [&](const std::string& why) {
        return Error{"geometry file " + s.path.string() + ": leaf " + std::to_string(leafIndex) + " (node " +
                         std::to_string(leaf.node) + "): " + why,
                     ErrorCode::BadFile};
    };
    // The node file's reader checked offset + size against the file's size.
    scratch.resize(leaf.chunkBytes);
    if (!detail::readAllAt(s.fd, scratch.data(), scratch.size(), leaf.offset))
        return bad("read failed (file truncated since it was opened?)");
    if (fnv1a64(scratch.data(), scratch.size()) != leaf.checksum) return bad("checksum mismatch (corrupt)");
    std::uint32_t head[4];
    if (scratch.size() < sizeof head) return bad("chunk shorter than its header");
    std::memcpy(head, scratch.data(), sizeof head);
    const std::uint32_t v = head[0], t = head[1], indexBytes = head[2];
    if (v != leaf.vertexCount || t != leaf.triangleCount) return bad("counts differ from the node file's");
    if ((indexBytes != 2 && indexBytes != 4) || head[3] != 0 || (indexBytes == 2 && v > 0x10000)) return bad("bad chunk header");
    const std::uint64_t raw = detail::kChunkHeaderBytes + std::uint64_t(v) * 24 + std::uint64_t(t) * 3 * indexBytes;
    if ((raw + 3) / 4 * 4 != scratch.size()) return bad("chunk size does not match its counts");
    const unsigned char* p = scratch.data() + detail::kChunkHeaderBytes;
    out.positions.resize(v);
    out.normals.resize(v);
    out.indices.resize(std::size_t(t) * 3);
    std::memcpy(out.positions.data(), p, std::size_t(v) * 12);
    p += std::size_t(v) * 12;
    std::memcpy(out.normals.data(), p, std::size_t(v) * 12);
    p += std::size_t(v) * 12;
    for (std::uint32_t& i : out.indices) {
        if (indexBytes == 2) {
            std::uint16_t x;
            std::memcpy(&x, p, 2);
            i = x;
        } else {
            std::memcpy(&i, p, 4);
        }
        p += indexBytes;
        if (i >= v) return bad("vertex index out of range");
    }
    for (std::uint32_t i = 0; i < v; ++i) {
        const glm::vec3 &q = out.positions[i], &n = out.normals[i];
        if (!(q.x >= leaf.box.min.x && q.x <= leaf.box.max.x && q.y >= leaf.box.min.y && q.y <= leaf.box.max.y &&
              q.z >= leaf.box.min.z && q.z <= leaf.box.max.z))
            return bad("vertex " + std::to_string(i) + " outside the leaf's box (or not finite)");
        if (!std::isfinite(n.x) || !std::isfinite(n.y) || !std::isfinite(n.z)) return bad("non-finite normal");
    }
    return {};
}

Status GeometryFile::readCompact(std::uint32_t leafIndex, CompactLeaf& out, Mesh& decoded,
                                 std::vector<unsigned char>& scratch) const {
    if (Status st = read(leafIndex, decoded, scratch); !st) return st;
    compactLeaf(decoded, s_->leaves[leafIndex].box, out);
    return {};
}

}  // namespace dyncull
