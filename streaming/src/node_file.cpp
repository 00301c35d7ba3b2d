// The node file of a streamed model and the writer of the pair (layout in
// streamed_model.hpp). The reader trusts nothing: header, size and checksum first, then
// every count against the bytes left, then the tree and leaf table checked by brute force
// (tiling, reachability, boxes, chunks inside the geometry file and not overlapping).
#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <fstream>

#include "dyncull/bsp/subdivision_file.hpp"
#include "dyncull/objects/binary_file.hpp"
#include "dyncull/objects/checksum.hpp"
#include "dyncull/objects/checked_write.hpp"
#include "dyncull/streaming/streamed_model.hpp"
#include "geometry_chunk.hpp"

namespace dyncull {
namespace {

constexpr char kNodeMagic[8] = {'D', 'Y', 'N', 'C', 'N', 'O', 'D', '\0'};
constexpr std::size_t kLeafBytes = 4 * 4 + 2 * 8 + 2 * 12 + (12 + 36 + 12 + 4);

Error badNodes(const std::filesystem::path& path, const std::string& why) {
    return Error{"node file " + path.string() + ": " + why, ErrorCode::BadFile};
}

std::filesystem::path tmpPath(std::filesystem::path p) {
    p += ".tmp";
    return p;
}

/// The tree and leaf table, checked by brute force: the writer's self-check and the
/// reader's defence. "" or the first problem.
std::string checkTree(const StreamedModel& m) {
    const std::size_t n = m.nodes.size();
    if (n == 0) return "no nodes";
    const std::uint64_t tris = m.nodes[0].triangleCount;
    if (m.nodes[0].firstTriangle != 0) return "root does not start at triangle 0";
    std::vector<std::uint8_t> reached(n, 0);
    reached[0] = 1;
    std::vector<std::uint32_t> leafNodes;
    for (std::size_t i = 0; i < n; ++i) {
        const SubdivisionNode& v = m.nodes[i];
        const std::string at = "node " + std::to_string(i) + ": ";
        if (!reached[i]) return at + "not reachable from the root (or reached twice)";
        if (std::uint64_t{v.firstTriangle} + v.triangleCount > tris) return at + "triangle range out of range";
        if (v.depth > kSubdivisionMaxDepth) return at + "depth out of range";
        if (!v.box.empty() && !v.box.finite()) return at + "non-finite box";
        if (v.isLeaf()) {
            if (v.firstChild != kInvalidIndex) return at + "leaf with a child index";
            if (v.triangleCount > 0) leafNodes.push_back(static_cast<std::uint32_t>(i));
            continue;
        }
        if (v.childCount < 2) return at + "inner node with fewer than two children";
        if (v.firstChild <= i || v.firstChild > n || v.childCount > n - v.firstChild) return at + "children out of range";
        std::uint64_t next = v.firstTriangle;  // 64-bit: a corrupt count cannot wrap
        Aabb box;
        for (std::uint32_t c = 0; c < v.childCount; ++c) {
            const std::size_t k = std::size_t{v.firstChild} + c;
            if (reached[k]) return at + "child " + std::to_string(k) + " has two parents";
            reached[k] = 1;
            if (m.nodes[k].firstTriangle != next) return at + "children do not tile its triangle range";
            next += m.nodes[k].triangleCount;
            box.extend(m.nodes[k].box);
        }
        if (next != std::uint64_t{v.firstTriangle} + v.triangleCount) return at + "children do not tile its triangle range";
        if (!(box.min == v.box.min && box.max == v.box.max)) return at + "box is not the union of its children";
    }
    // Leaves: one per non-empty leaf node, in leaf order, chunks inside the file, apart.
    std::sort(leafNodes.begin(), leafNodes.end(),
              [&](std::uint32_t a, std::uint32_t b) { return m.nodes[a].firstTriangle < m.nodes[b].firstTriangle; });
    if (m.leaves.size() != leafNodes.size())
        return std::to_string(m.leaves.size()) + " leaves for " + std::to_string(leafNodes.size()) + " leaf nodes";
    struct Chunk {
        std::uint64_t begin, end;
        std::size_t leaf;
        bool operator<(const Chunk& o) const { return begin < o.begin; }
    };
    std::vector<Chunk> chunks;
    chunks.reserve(m.leaves.size());
    for (std::size_t i = 0; i < m.leaves.size(); ++i) {
        const StreamedLeaf& l = m.leaves[i];
        const std::string at = "leaf " + std::to_string(i) + ": ";
        if (l.node != leafNodes[i]) return at + "not the leaf node " + std::to_string(leafNodes[i]) + " of leaf order";
        const SubdivisionNode& v = m.nodes[l.node];
        if (l.triangleCount != v.triangleCount) return at + "triangle count differs from its node's";
        if (l.vertexCount == 0 || l.chunkBytes < detail::kChunkHeaderBytes || l.chunkBytes > kMaxLeafChunkBytes)
            return at + "bad vertex count or chunk size";
        if (l.offset < kStreamedHeaderSize || l.offset > m.geometryBytes || l.chunkBytes > m.geometryBytes - l.offset)
            return at + "chunk outside the geometry file";
        if (!(l.box.min == v.box.min && l.box.max == v.box.max)) return at + "box differs from its node's";
        const Obb& o = l.obb;
        for (int k = 0; k < 3; ++k)
            if (!std::isfinite(o.center[k]) || !(o.halfExtents[k] >= 0.0f) || !std::isfinite(o.halfExtents[k]))
                return at + "malformed PCA box";
        for (int c = 0; c < 3; ++c)
            if (std::fabs(glm::length(o.axes[c]) - 1.0f) > 1e-3f) return at + "PCA box axes are not unit";
        chunks.push_back({l.offset, l.offset + l.chunkBytes, i});
    }
    std::sort(chunks.begin(), chunks.end());
    for (std::size_t i = 1; i < chunks.size(); ++i)
        if (chunks[i].begin < chunks[i - 1].end)
            return "leaf " + std::to_string(chunks[i].leaf) + "'s chunk overlaps leaf " + std::to_string(chunks[i - 1].leaf) + "'s";
    return {};
}

}  // namespace

std::uint32_t StreamedModel::largestChunk() const {
    std::uint32_t most = 0;
    for (const StreamedLeaf& l : leaves) most = std::max(most, l.chunkBytes);
    return most;
}

std::filesystem::path geometryPathFor(const std::filesystem::path& nodePath) {
    std::filesystem::path p = nodePath;
    p.replace_extension(".dgeom");
    return p;
}

struct StreamedModelWriter::State {
    std::filesystem::path nodePath, geometryPath;
    int fd = -1;
    bool finished = false;
    std::uint64_t end = kStreamedHeaderSize;  // next chunk's offset
    std::uint64_t idHash = kFnv1a64Seed;      // over every chunk's checksum: the pair's id
    std::vector<StreamedLeaf> leaves;
    std::vector<unsigned char> chunk;
    ~State() {
        if (fd >= 0) ::close(fd);
        if (!finished) {
            std::error_code ec;
            std::filesystem::remove(tmpPath(geometryPath), ec);
            std::filesystem::remove(tmpPath(nodePath), ec);
        }
    }
};

StreamedModelWriter::StreamedModelWriter(std::unique_ptr<State> s) : s_(std::move(s)) {}
StreamedModelWriter::StreamedModelWriter(StreamedModelWriter&&) noexcept = default;
StreamedModelWriter& StreamedModelWriter::operator=(StreamedModelWriter&&) noexcept = default;
StreamedModelWriter::~StreamedModelWriter() = default;

const std::vector<StreamedLeaf>& StreamedModelWriter::leaves() const { return s_->leaves; }
std::uint64_t StreamedModelWriter::geometryBytes() const { return s_->end; }

Expected<StreamedModelWriter> StreamedModelWriter::create(const std::filesystem::path& nodePath) {
    auto s = std::make_unique<State>();
    s->nodePath = nodePath;
    s->geometryPath = geometryPathFor(nodePath);
    const auto tmp = tmpPath(s->geometryPath);
    s->fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
    if (s->fd < 0) return Error{"geometry file " + tmp.string() + ": cannot create: " + std::strerror(errno), ErrorCode::Io};
    return StreamedModelWriter(std::move(s));
}

Expected<std::uint32_t> StreamedModelWriter::addLeaf(const Mesh& g, std::uint32_t node) {
    State& s = *s_;
    const auto tmp = tmpPath(s.geometryPath);
    if (s.leaves.size() >= 0xFFFFFFFEu) return Error{"geometry file " + tmp.string() + ": too many leaves", ErrorCode::BadArgument};
    if (std::string why = detail::encodeChunk(g, s.chunk); !why.empty())
        return Error{"geometry file " + tmp.string() + ": leaf " + std::to_string(s.leaves.size()) + ": " + why,
                     ErrorCode::BadArgument};
    if (!detail::writeAllAt(s.fd, s.chunk.data(), s.chunk.size(), s.end))
        return Error{"geometry file " + tmp.string() + ": write failed: " + std::strerror(errno), ErrorCode::Io};
    StreamedLeaf leaf;
    leaf.node = node;
    leaf.vertexCount = static_cast<std::uint32_t>(g.positions.size());
    leaf.triangleCount = static_cast<std::uint32_t>(g.indices.size() / 3);
    leaf.chunkBytes = static_cast<std::uint32_t>(s.chunk.size());
    leaf.offset = s.end;
    leaf.checksum = fnv1a64(s.chunk.data(), s.chunk.size());
    for (const glm::vec3& p : g.positions) leaf.box.extend(p);
    leaf.obb = fitObbPca(g.positions);
    s.idHash = fnv1a64(&leaf.checksum, sizeof leaf.checksum, s.idHash);
    s.end += s.chunk.size();
    s.leaves.push_back(leaf);
    return static_cast<std::uint32_t>(s.leaves.size() - 1);
}

Status StreamedModelWriter::finish(StreamedModel& m) {
    State& s = *s_;
    const auto geoTmp = tmpPath(s.geometryPath), nodeTmp = tmpPath(s.nodePath);
    // The tree's leaves are in leaf order; the writer saw them in the order they were made.
    m.leaves = s.leaves;
    std::sort(m.leaves.begin(), m.leaves.end(), [&](const StreamedLeaf& a, const StreamedLeaf& b) {
        return m.nodes[a.node].firstTriangle < m.nodes[b.node].firstTriangle;
    });
    m.geometryBytes = s.end;
    m.geometryId = fnv1a64(&s.end, sizeof s.end, s.idHash);
    if (std::string why = checkTree(m); !why.empty()) return Error{"streamed model " + s.nodePath.string() + ": " + why};

    unsigned char gh[kStreamedHeaderSize];
    detail::encodeGeometryHeader(m.geometryId, s.end, gh);
    if (!detail::writeAllAt(s.fd, gh, sizeof gh, 0))
        return Error{"geometry file " + geoTmp.string() + ": write failed: " + std::strerror(errno), ErrorCode::Io};
    const int fd = s.fd;
    s.fd = -1;
    if (::fsync(fd) != 0 || ::close(fd) != 0)
        return Error{"geometry file " + geoTmp.string() + ": write failed on close: " + std::strerror(errno), ErrorCode::Io};

    {
        std::ofstream f;
        if (Status st = openChecked(f, nodeTmp); !st) return st;
        const char zeros[kStreamedHeaderSize] = {};
        f.write(zeros, sizeof zeros);
        BinaryWriter w(f);
        w.str<std::uint32_t>(m.source);
        w.put(m.sourceHash);
        writeSubdivisionParams(w, m.params);
        w.put(m.geometryBytes);
        w.put(static_cast<std::uint32_t>(m.nodes.size()));
        for (const SubdivisionNode& n : m.nodes) writeSubdivisionNode(w, n);
        w.put(static_cast<std::uint32_t>(m.leaves.size()));
        for (const StreamedLeaf& l : m.leaves) {
            w.put(l.node);
            w.put(l.vertexCount);
            w.put(l.triangleCount);
            w.put(l.chunkBytes);
            w.put(l.offset);
            w.put(l.checksum);
            w.put(l.box.min);
            w.put(l.box.max);
            w.put(l.obb.center);
            w.put(l.obb.axes);
            w.put(l.obb.halfExtents);
            w.put(static_cast<std::uint32_t>(l.obb.isAabb));
        }
        const std::uint64_t payload = w.size(), sum = w.hash();
        const std::uint32_t version = kStreamedModelVersion, headerSize = kStreamedHeaderSize;
        char h[kStreamedHeaderSize];
        std::memcpy(h, kNodeMagic, 8);
        std::memcpy(h + 8, &version, 4);
        std::memcpy(h + 12, &headerSize, 4);
        const std::uint64_t reserved = 0;
        std::memcpy(h + 16, &reserved, 8);
        std::memcpy(h + 24, &payload, 8);
        std::memcpy(h + 32, &sum, 8);
        std::memcpy(h + 40, &m.geometryId, 8);
        f.seekp(0);
        f.write(h, sizeof h);
        if (Status st = closeChecked(f, nodeTmp); !st) return st;
    }
    std::error_code ec;
    std::filesystem::rename(geoTmp, s.geometryPath, ec);
    if (!ec) std::filesystem::rename(nodeTmp, s.nodePath, ec);
    if (ec) return Error{"streamed model " + s.nodePath.string() + ": cannot rename into place: " + ec.message(), ErrorCode::Io};
    s.finished = true;
    m.nodePath = s.nodePath;
    m.geometryPath = s.geometryPath;
    return {};
}

Expected<StreamedModel> readStreamedModel(const std::filesystem::path& path) {
    std::ifstream f(path, std::ios::binary | std::ios::ate);
    if (!f) return badNodes(path, "cannot open");
    const std::streamoff end = f.tellg();
    if (end < 0) return badNodes(path, "cannot size");
    const auto size = static_cast<std::uint64_t>(end);
    if (size < kStreamedHeaderSize) return badNodes(path, "truncated header (" + std::to_string(size) + " bytes)");
    char h[kStreamedHeaderSize];
    f.seekg(0);
    f.read(h, sizeof h);
    if (!f) return badNodes(path, "cannot read header");
    if (std::memcmp(h, kNodeMagic, 8) != 0) return badNodes(path, "bad magic (not a dyncull node file)");
    std::uint32_t version = 0, headerSize = 0;
    StreamedModel m;
    std::uint64_t payload = 0, sum = 0, reserved = 0;
    std::memcpy(&version, h + 8, 4);
    std::memcpy(&headerSize, h + 12, 4);
    std::memcpy(&reserved, h + 16, 8);
    std::memcpy(&payload, h + 24, 8);
    std::memcpy(&sum, h + 32, 8);
    std::memcpy(&m.geometryId, h + 40, 8);
    if (version != kStreamedModelVersion)
        return badNodes(path, "format version " + std::to_string(version) + ", expected " + std::to_string(kStreamedModelVersion));
    if (headerSize != kStreamedHeaderSize || reserved != 0) return badNodes(path, "bad header");
    if (payload != size - kStreamedHeaderSize)
        return badNodes(path, "truncated or padded: header says " + std::to_string(payload) + " payload bytes, file has " +
                                  std::to_string(size - kStreamedHeaderSize));
    if (std::string why = checkPayload(f, payload, sum); !why.empty()) return badNodes(path, why);
    f.seekg(static_cast<std::streamoff>(kStreamedHeaderSize));

    BinaryReader r(f, payload);
    if (!r.str<std::uint32_t>(m.source, 4096)) return badNodes(path, "truncated source name");
    m.sourceHash = r.get<std::uint64_t>();
    if (std::string why = readSubdivisionParams(r, m.params); !why.empty()) return badNodes(path, why);
    m.geometryBytes = r.get<std::uint64_t>();
    const auto nodes = r.get<std::uint32_t>();
    if (r.failed() || nodes == 0 || nodes > r.left() / kSubdivisionNodeBytes) return badNodes(path, "node count out of range");
    m.nodes.resize(nodes);
    for (SubdivisionNode& n : m.nodes) n = readSubdivisionNode(r);
    const auto leaves = r.get<std::uint32_t>();
    if (r.failed() || leaves > r.left() / kLeafBytes) return badNodes(path, "leaf count out of range");
    m.leaves.resize(leaves);
    for (StreamedLeaf& l : m.leaves) {
        l.node = r.get<std::uint32_t>();
        l.vertexCount = r.get<std::uint32_t>();
        l.triangleCount = r.get<std::uint32_t>();
        l.chunkBytes = r.get<std::uint32_t>();
        l.offset = r.get<std::uint64_t>();
        l.checksum = r.get<std::uint64_t>();
        l.box.min = r.get<glm::vec3>();
        l.box.max = r.get<glm::vec3>();
        l.obb.center = r.get<glm::vec3>();
        l.obb.axes = r.get<glm::mat3>();
        l.obb.halfExtents = r.get<glm::vec3>();
        const auto isAabb = r.get<std::uint32_t>();
        if (isAabb > 1) return badNodes(path, "malformed PCA box");
        l.obb.isAabb = isAabb != 0;
    }
    if (r.failed()) return badNodes(path, "truncated leaf table");
    if (r.left() != 0) return badNodes(path, std::to_string(r.left()) + " trailing payload bytes");
    if (std::string why = checkTree(m); !why.empty()) return badNodes(path, why);

    // The geometry file: there, the same pair, the size the leaves need.
    m.nodePath = path;
    m.geometryPath = geometryPathFor(path);
    const std::string gname = "geometry file " + m.geometryPath.string() + ": ";
    std::ifstream g(m.geometryPath, std::ios::binary | std::ios::ate);
    if (!g) return Error{gname + "cannot open", ErrorCode::BadFile};
    const std::streamoff gend = g.tellg();
    unsigned char gh[kStreamedHeaderSize], expect[kStreamedHeaderSize];
    g.seekg(0);
    g.read(reinterpret_cast<char*>(gh), sizeof gh);
    if (!g || gend < 0) return Error{gname + "truncated header", ErrorCode::BadFile};
    detail::encodeGeometryHeader(m.geometryId, m.geometryBytes, expect);
    if (std::memcmp(gh, detail::kGeometryMagic, 8) != 0) return Error{gname + "bad magic (not a dyncull geometry file)", ErrorCode::BadFile};
    if (std::memcmp(gh, expect, sizeof gh) != 0)
        return Error{gname + "does not belong to " + path.string() + " (other version or geometry id)", ErrorCode::BadFile};
    if (static_cast<std::uint64_t>(gend) != m.geometryBytes)
        return Error{gname + "truncated or padded: " + std::to_string(gend) + " bytes, the node file expects " +
                         std::to_string(m.geometryBytes),
                     ErrorCode::BadFile};
    return m;
}

}  // namespace dyncull
