// Out-of-core subdivision (out_of_core_subdivision.hpp for the passes).
// Paper: Out-of-core interactive display of large meshes using an oriented bounding
// box-based hardware depth query, section 4 (subdivision under a memory limit, LRU vertex
// cache, separate subdivision and data files); the in-memory subtrees use Scene
// subdivision for occlusion culling, section 3.
#include "dyncull/streaming/out_of_core_subdivision.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstring>

#include "dyncull/objects/polygon_triangulation.hpp"
#include "temp_files.hpp"

namespace dyncull {
namespace {

using detail::BlockCache;
using detail::RecordReader;
using detail::RecordWriter;

constexpr std::size_t kIoBuffer = std::size_t{1} << 20;
/// Histogram resolution of a streamed split's median search: the median is found to
/// 1/1024 of the node's centroid extent, which balances the halves to well within a percent.
constexpr int kBins = 1024;
/// Memory of an in-memory subtree per triangle, an estimate with room to spare (the
/// preprocessing runs in docs/BENCHMARKS.md peak well under their budgets): the records
/// (48), vertex ids sorted for the mesh (12 + 4), the mesh (indices 12, positions and
/// normals 24 per vertex, up to 3 vertices per triangle), the subdivision's work arrays
/// (SubdivisionStats::workBytes, about 60) and the leaf meshes with meshoptimizer's
/// scratch (about the mesh again).
constexpr std::size_t kSubtreeBytesPerTriangle = 400;

double msSince(std::chrono::steady_clock::time_point t) {
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t).count();
}

/// One triangle between the passes: corner positions (for splitting without lookups)
/// and the source's vertex ids (for rebuilding shared vertices and looking normals up).
struct TriRecord {
    glm::vec3 p[3];
    std::uint32_t v[3];
    glm::vec3 centroid() const { return (p[0] + p[1] + p[2]) * (1.0f / 3.0f); }
};
static_assert(sizeof(TriRecord) == 48);

/// Centroid counts along each axis over a fixed range, gathered while a node's records
/// are written so its split needs no extra pass.
struct Histogram {
    Aabb range;  ///< contains every centroid counted
    std::array<std::array<std::uint32_t, kBins>, 3> counts{};
    int bin(int axis, float c) const {
        const float lo = range.min[axis], ext = range.max[axis] - lo;
        if (!(ext > 0.0f)) return 0;
        const int b = static_cast<int>((c - lo) / ext * kBins);
        return std::clamp(b, 0, kBins - 1);
    }
    void add(const glm::vec3& c) {
        for (int a = 0; a < 3; ++a) ++counts[a][bin(a, c[a])];
    }
};

/// A node waiting for the subdivision: its records in a file of its own.
struct Work {
    std::uint32_t node = 0;
    std::filesystem::path file;
    std::uint64_t count = 0;
    std::uint32_t depth = 0;
    Aabb box, centroids;
    std::unique_ptr<Histogram> histogram;
};

/// Pass 1: the source into a position file, a normal file and a polygon file.
class ParseSink final : public MeshStreamSink {
public:
    RecordWriter positions, normals, polygons;
    MeshStreamLayout layout;
    Aabb box;  // of every vertex: bounds the centroids, the root histogram's range
    std::uint64_t vertices = 0, polygonCount = 0, corners = 0;
    bool normalsUsable = true;  // every source normal finite and non-zero
    const OutOfCoreProgress* progressFn = nullptr;

    Status begin(const MeshStreamLayout& l) override {
        layout = l;
        normalsUsable = l.normals;
        return {};
    }
    Status vertex(const glm::vec3& p, const glm::vec3& n) override {
        ++vertices;
        box.extend(p);
        if (Status s = positions.write(&p, sizeof p); !s) return s;
        if (normalsUsable) {
            const float len = glm::length(n);
            if (!(len > 0.0f) || !std::isfinite(len)) {
                normalsUsable = false;  // the source's normals are not all usable: recompute all, as loaders do
                return {};
            }
            const glm::vec3 u = n / len;
            return normals.write(&u, sizeof u);
        }
        return {};
    }
    Status face(std::span<const std::uint32_t> c) override {
        ++polygonCount;
        corners += c.size();
        const auto n = static_cast<std::uint32_t>(c.size());
        if (Status s = polygons.write(&n, sizeof n); !s) return s;
        return polygons.write(c.data(), c.size_bytes());
    }
    void progress(std::uint64_t done) override {
        if (*progressFn) (*progressFn)("reading", static_cast<double>(done), static_cast<double>(std::max<std::uint64_t>(layout.bytes, 1)));
    }
};

class Builder {
public:
    Builder(const OutOfCoreParams& p, const OutOfCoreProgress& progress, detail::TempDirectory& temp,
            StreamedModelWriter& writer)
        : params_(p), progress_(progress), temp_(temp), writer_(writer) {}

    Status run(const MeshStreamSource& source);
    OutOfCoreStats stats;
    std::vector<SubdivisionNode> nodes;

private:
    Status parse(const MeshStreamSource& source);
    Status triangulate();
    Status build();
    Status split(Work& w);
    Status buildInMemory(Work& w);
    Status readRecords(const Work& w, std::vector<TriRecord>& out);
    std::filesystem::path newFile() { return temp_.path() / ("part" + std::to_string(files_++) + ".bin"); }
    void report(const char* phase, double done, double total) {
        if (progress_) progress_(phase, done, total);
    }

    const OutOfCoreParams& params_;
    const OutOfCoreProgress& progress_;
    detail::TempDirectory& temp_;
    StreamedModelWriter& writer_;
    std::uint64_t files_ = 0;
    std::filesystem::path positionsPath_, normalsPath_, polygonsPath_;
    bool computeNormals_ = false;
    Aabb vertexBox_;
    BlockCache<glm::vec3> normalCache_;
    std::vector<Work> stack_;
    std::uint64_t nextTriangle_ = 0;  // leaf order position of the next leaf's first triangle
};

Status Builder::run(const MeshStreamSource& source) {
    if (Status s = parse(source); !s) return s;
    if (Status s = triangulate(); !s) return s;
    return build();
}

Status Builder::parse(const MeshStreamSource& source) {
    const auto t0 = std::chrono::steady_clock::now();
    ParseSink sink;
    sink.progressFn = &progress_;
    positionsPath_ = temp_.path() / "positions.bin";
    normalsPath_ = temp_.path() / "normals.bin";
    polygonsPath_ = temp_.path() / "polygons.bin";
    if (Status s = sink.positions.open(positionsPath_, kIoBuffer); !s) return s;
    if (Status s = sink.normals.open(normalsPath_, kIoBuffer); !s) return s;
    if (Status s = sink.polygons.open(polygonsPath_, kIoBuffer); !s) return s;
    if (Status s = source(sink); !s) return s;
    for (RecordWriter* w : {&sink.positions, &sink.normals, &sink.polygons})
        if (Status s = w->close(); !s) return s;
    stats.vertices = sink.vertices;
    stats.polygons = sink.polygonCount;
    stats.tempBytesWritten += sink.positions.written() + sink.normals.written() + sink.polygons.written();
    if (sink.vertices == 0 || sink.polygonCount == 0) return Error{"the model has no triangles", ErrorCode::BadFile};
    if (sink.vertices > 0xFFFFFFFFull) return Error{"more than 2^32 vertices", ErrorCode::BadFile};
    vertexBox_ = sink.box;
    computeNormals_ = !sink.normalsUsable;
    stats.normalsFromSource = sink.normalsUsable;
    if (computeNormals_) {
        // Zeros to accumulate into (a sparse file: nothing is written until a block is).
        const int fd = ::open(normalsPath_.c_str(), O_WRONLY | O_TRUNC | O_CLOEXEC);
        const bool ok = fd >= 0 && ::ftruncate(fd, static_cast<off_t>(sink.vertices * sizeof(glm::vec3))) == 0;
        if (fd >= 0) ::close(fd);
        if (!ok) return Error{"temporary file " + normalsPath_.string() + ": cannot size", ErrorCode::Io};
    }
    stats.readMs = msSince(t0);
    return {};
}

Status Builder::triangulate() {
    const auto t0 = std::chrono::steady_clock::now();
    const std::size_t budget = params_.memoryBytes;
    // Half the budget to the two caches (position, normal), the rest for buffers.
    BlockCache<glm::vec3> positions;
    if (Status s = positions.open(positionsPath_, stats.vertices, budget / 4, false); !s) return s;
    if (computeNormals_)
        if (Status s = normalCache_.open(normalsPath_, stats.vertices, budget / 4, true); !s) return s;
    RecordReader polygons;
    if (Status s = polygons.open(polygonsPath_, kIoBuffer); !s) return s;
    Work root;
    root.file = newFile();
    root.histogram = std::make_unique<Histogram>();
    // Centroids lie in the box of the vertices, gathered in pass 1: that is the root
    // histogram's range. (Unused vertices may widen it; the median search copes.)
    root.histogram->range = vertexBox_;
    RecordWriter out;
    if (Status s = out.open(root.file, kIoBuffer); !s) return s;

    std::vector<std::uint32_t> corners, local;
    std::vector<glm::vec3> cornerPositions;
    TriangulationScratch scratch;
    std::uint64_t done = 0;
    std::uint32_t n = 0;
    while (polygons.read(&n, sizeof n)) {
        corners.resize(n);
        if (!polygons.read(corners.data(), std::size_t{n} * 4))
            return Error{"temporary file " + polygonsPath_.string() + ": short record", ErrorCode::Io};
        cornerPositions.resize(n);
        for (std::uint32_t k = 0; k < n; ++k) {
            auto p = positions.at(corners[k]);
            if (!p) return p.error();
            cornerPositions[k] = **p;
        }
        local.clear();
        if (n == 3) {
            local = {0, 1, 2};
        } else if (triangulatePolygon(cornerPositions, local, scratch) == Triangulation::TooComplex) {
            return Error{"polygon " + std::to_string(done) + " with " + std::to_string(n) +
                             " corners is too complex to triangulate",
                         ErrorCode::BadFile};
        }
        for (std::size_t t = 0; t + 2 < local.size(); t += 3) {
            TriRecord r;
            for (int c = 0; c < 3; ++c) {
                r.p[c] = cornerPositions[local[t + c]];
                r.v[c] = corners[local[t + c]];
            }
            if (Status s = out.write(&r, sizeof r); !s) return s;
            root.box.extend(r.p[0]);
            root.box.extend(r.p[1]);
            root.box.extend(r.p[2]);
            const glm::vec3 c = r.centroid();
            root.centroids.extend(c);
            root.histogram->add(c);
            ++root.count;
            if (computeNormals_) {
                // Unnormalised cross product = 2 * area * normal, as computeNormals weighs them.
                const glm::vec3 fn = glm::cross(r.p[1] - r.p[0], r.p[2] - r.p[0]);
                for (int c2 = 0; c2 < 3; ++c2) {
                    auto q = normalCache_.at(r.v[c2]);
                    if (!q) return q.error();
                    **q += fn;
                }
            }
        }
        if ((++done & 0xFFFF) == 0) report("triangulating", static_cast<double>(done), static_cast<double>(stats.polygons));
    }
    report("triangulating", static_cast<double>(stats.polygons), static_cast<double>(stats.polygons));
    if (Status s = out.close(); !s) return s;
    if (computeNormals_)
        if (Status s = normalCache_.flush(); !s) return s;
    stats.cacheLookups += positions.lookups() + normalCache_.lookups();
    stats.cacheMisses += positions.misses() + normalCache_.misses();
    stats.tempBytesRead += polygons.bytesRead() + positions.bytesRead() + normalCache_.bytesRead();
    stats.tempBytesWritten += out.written() + normalCache_.bytesWritten();
    normalCache_.close();
    stats.triangles = root.count;
    if (root.count == 0) return Error{"the model has no triangles (every polygon has zero area)", ErrorCode::BadFile};
    if (root.count > 0xFFFFFFFEull) return Error{"more than 2^32 - 2 triangles", ErrorCode::BadFile};
    std::error_code ec;
    std::filesystem::remove(polygonsPath_, ec);
    std::filesystem::remove(positionsPath_, ec);

    nodes.push_back(SubdivisionNode{});
    root.node = 0;
    stack_.push_back(std::move(root));
    stats.triangulateMs = msSince(t0);
    return {};
}

Status Builder::build() {
    const auto t0 = std::chrono::steady_clock::now();
    // The normal cache keeps a quarter of the budget; the subtree in memory the rest but
    // the file buffers (three) and a fixed reserve for small allocations.
    if (Status s = normalCache_.open(normalsPath_, stats.vertices, params_.memoryBytes / 4, false); !s) return s;
    const std::size_t reserve = 3 * kIoBuffer + (std::size_t{4} << 20);
    const std::size_t forSubtree = params_.memoryBytes - params_.memoryBytes / 4 - std::min(reserve, params_.memoryBytes / 4);
    stats.subtreeLimit = std::max<std::uint64_t>(forSubtree / kSubtreeBytesPerTriangle, params_.subdivision.maxLeafTriangles);
    while (!stack_.empty()) {
        Work w = std::move(stack_.back());
        stack_.pop_back();
        SubdivisionNode& node = nodes[w.node];
        node.box = w.box;
        node.depth = w.depth;
        node.firstTriangle = static_cast<std::uint32_t>(nextTriangle_);
        node.triangleCount = static_cast<std::uint32_t>(w.count);
        const bool fits = w.count <= stats.subtreeLimit || w.depth >= params_.subdivision.maxDepth;
        if (Status s = fits ? buildInMemory(w) : split(w); !s) return s;
        std::error_code ec;
        std::filesystem::remove(w.file, ec);
        report("subdividing", static_cast<double>(nextTriangle_), static_cast<double>(stats.triangles));
    }
    stats.cacheLookups += normalCache_.lookups();
    stats.cacheMisses += normalCache_.misses();
    stats.tempBytesRead += normalCache_.bytesRead();
    normalCache_.close();
    stats.nodes = static_cast<std::uint32_t>(nodes.size());
    stats.leaves = static_cast<std::uint32_t>(writer_.leaves().size());
    stats.geometryBytes = writer_.geometryBytes();
    stats.buildMs = msSince(t0);
    return {};
}

Status Builder::split(Work& w) {
    ++stats.streamedSplits;
    // The axis of the longest centroid extent, cut at the median bin boundary.
    const glm::vec3 ext = w.centroids.max - w.centroids.min;
    const int axis = ext.x >= ext.y && ext.x >= ext.z ? 0 : (ext.y >= ext.z ? 1 : 2);
    const Histogram& h = *w.histogram;
    std::uint64_t below = 0;
    int cut = 0;  // centroids in bins < cut go left
    while (cut < kBins && below + h.counts[axis][cut] <= w.count / 2) below += h.counts[axis][cut++];
    if (below == 0 && cut < kBins) below += h.counts[axis][cut++];  // at least one bin left
    // All centroids in one bin (coincident centroids, or a range too wide): cut by record
    // position instead, which always halves the node.
    const bool byPosition = below == 0 || below == w.count;
    const float plane = h.range.min[axis] + (h.range.max[axis] - h.range.min[axis]) * static_cast<float>(cut) / kBins;

    Work child[2];
    RecordWriter out[2];
    for (int c = 0; c < 2; ++c) {
        child[c].file = newFile();
        child[c].depth = w.depth + 1;
        child[c].histogram = std::make_unique<Histogram>();
        // A child's centroids lie in the parent's centroid box, cut at the plane.
        child[c].histogram->range = w.centroids;
        if (!byPosition) (c == 0 ? child[c].histogram->range.max : child[c].histogram->range.min)[axis] = plane;
        if (Status s = out[c].open(child[c].file, kIoBuffer); !s) return s;
    }
    RecordReader in;
    if (Status s = in.open(w.file, kIoBuffer); !s) return s;
    TriRecord r;
    std::uint64_t i = 0;
    while (in.read(&r, sizeof r)) {
        const glm::vec3 c = r.centroid();
        // The bin test, not `c < plane`: the same float arithmetic as the histogram, so the
        // left count is exactly `below`.
        const int side = byPosition ? (i >= w.count / 2) : (h.bin(axis, c[axis]) >= cut);
        ++i;
        Work& k = child[side];
        if (Status s = out[side].write(&r, sizeof r); !s) return s;
        for (int v = 0; v < 3; ++v) k.box.extend(r.p[v]);
        k.centroids.extend(c);
        k.histogram->add(c);
        ++k.count;
    }
    stats.tempBytesRead += in.bytesRead();
    if (i != w.count) return Error{"temporary file " + w.file.string() + ": short read", ErrorCode::Io};
    for (RecordWriter& o : out) {
        stats.tempBytesWritten += o.written();
        if (Status s = o.close(); !s) return s;
    }
    const auto first = static_cast<std::uint32_t>(nodes.size());
    nodes[w.node].firstChild = first;
    nodes[w.node].childCount = 2;
    nodes.resize(nodes.size() + 2);
    child[0].node = first;
    child[1].node = first + 1;
    // Right first: the stack pops the left child next, so leaves come in tree order.
    stack_.push_back(std::move(child[1]));
    stack_.push_back(std::move(child[0]));
    return {};
}

Status Builder::readRecords(const Work& w, std::vector<TriRecord>& out) {
    out.resize(static_cast<std::size_t>(w.count));
    RecordReader in;
    if (Status s = in.open(w.file, kIoBuffer); !s) return s;
    if (!in.read(out.data(), out.size() * sizeof(TriRecord)))
        return Error{"temporary file " + w.file.string() + ": short read", ErrorCode::Io};
    stats.tempBytesRead += in.bytesRead();
    return {};
}

Status Builder::buildInMemory(Work& w) {
    ++stats.memorySubtrees;
    stats.largestSubtree = std::max(stats.largestSubtree, w.count);
    Mesh mesh;
    std::vector<std::uint32_t> ids;
    {
        std::vector<TriRecord> records;
        if (Status s = readRecords(w, records); !s) return s;
        // Shared vertices again: the source's ids, sorted, are the subtree's vertex numbering.
        ids.reserve(records.size() * 3);
        for (const TriRecord& r : records) ids.insert(ids.end(), r.v, r.v + 3);
        std::sort(ids.begin(), ids.end());
        ids.erase(std::unique(ids.begin(), ids.end()), ids.end());
        ids.shrink_to_fit();
        mesh.positions.resize(ids.size());
        mesh.indices.reserve(records.size() * 3);
        for (const TriRecord& r : records)
            for (int c = 0; c < 3; ++c) {
                const auto k = static_cast<std::uint32_t>(std::lower_bound(ids.begin(), ids.end(), r.v[c]) - ids.begin());
                mesh.positions[k] = r.p[c];
                mesh.indices.push_back(k);
            }
    }
    mesh.normals.resize(ids.size());
    for (std::size_t k = 0; k < ids.size(); ++k) {
        auto n = normalCache_.at(ids[k]);  // ids ascend: the cache reads each block once
        if (!n) return n.error();
        const glm::vec3 v = **n;
        const float len = glm::length(v);
        // As computeNormals: a vertex touching only degenerate triangles gets +Z.
        mesh.normals[k] = (len > 0.0f && std::isfinite(len)) ? v / len : glm::vec3(0.0f, 0.0f, 1.0f);
    }
    std::vector<std::uint32_t>().swap(ids);

    SubdivisionParams sp = params_.subdivision;
    sp.maxDepth = std::max<std::uint32_t>(1, params_.subdivision.maxDepth - std::min(w.depth, params_.subdivision.maxDepth));
    auto sub = subdivide(mesh, sp);
    if (!sub) return sub.error();
    // subdivide numbers its root 0 and the rest from 1: ours are w.node and base + i - 1.
    const auto base = static_cast<std::uint32_t>(nodes.size());
    const auto global = [&](std::uint32_t i) { return i == 0 ? w.node : base + i - 1; };
    nodes.resize(nodes.size() + sub->nodes.size() - 1);
    for (std::uint32_t i = 0; i < sub->nodes.size(); ++i) {
        const SubdivisionNode& s = sub->nodes[i];
        SubdivisionNode& g = nodes[global(i)];
        g.box = s.box;
        g.childCount = s.childCount;
        g.firstChild = s.isLeaf() ? kInvalidIndex : global(s.firstChild);
        g.firstTriangle = static_cast<std::uint32_t>(nextTriangle_ + s.firstTriangle);
        g.triangleCount = s.triangleCount;
        g.depth = w.depth + s.depth;
    }
    // Leaves as subdivisionLeafModels makes them for in-memory models: compact, in
    // optimizeLeafOrder's order. Drawn two-sided: no leaf knows whether the whole surface
    // is closed, and the whole is never in memory to tell.
    std::vector<LocalBsp> leaves = subdivisionLeafModels(mesh, *sub, FaceMode::TwoSided);
    std::size_t next = 0;
    Mesh g;
    for (std::uint32_t i = 0; i < sub->nodes.size(); ++i) {
        const SubdivisionNode& s = sub->nodes[i];
        if (!s.isLeaf() || s.triangleCount == 0) continue;
        Mesh& m = leaves[next++].mesh;
        g.positions = std::move(m.positions);
        g.normals = std::move(m.normals);
        g.indices = std::move(m.indices);
        if (auto leaf = writer_.addLeaf(g, global(i)); !leaf) return leaf.error();
    }
    nextTriangle_ += w.count;
    return {};
}

}  // namespace

MeshStreamSource meshSource(const Mesh& mesh) {
    return [&mesh](MeshStreamSink& sink) -> Status {
        MeshStreamLayout l;
        l.vertices = mesh.positions.size();
        l.faces = mesh.triangleCount();
        l.normals = mesh.normals.size() == mesh.positions.size();
        l.bytes = l.vertices * 24 + l.faces * 12;
        if (Status s = sink.begin(l); !s) return s;
        const glm::vec3 zero(0.0f);
        for (std::size_t i = 0; i < mesh.positions.size(); ++i)
            if (Status s = sink.vertex(mesh.positions[i], l.normals ? mesh.normals[i] : zero); !s) return s;
        for (std::size_t t = 0; t < mesh.triangleCount(); ++t) {
            if (Status s = sink.face({mesh.indices.data() + 3 * t, 3}); !s) return s;
            if ((t & 0xFFFFF) == 0) sink.progress(l.vertices * 24 + t * 12);
        }
        sink.progress(l.bytes);
        return {};
    };
}

Expected<OutOfCoreStats> subdivideOutOfCore(const MeshStreamSource& source, const std::filesystem::path& nodePath,
                                            const OutOfCoreParams& params, const OutOfCoreProgress& progress) {
    if (Status s = validateSubdivisionParams(params.subdivision); !s) return s.error();
    if (params.memoryBytes < (std::size_t{16} << 20))
        return Error{"memory budget " + std::to_string(params.memoryBytes >> 20) + " MiB is below the minimum of 16 MiB",
                     ErrorCode::BadArgument};
    const auto parent = params.tempDirectory.empty() ? nodePath.parent_path() : params.tempDirectory;
    auto temp = detail::TempDirectory::create(parent.empty() ? std::filesystem::path(".") : parent,
                                              nodePath.filename().string());
    if (!temp) return temp.error();
    auto writer = StreamedModelWriter::create(nodePath);
    if (!writer) return writer.error();
    Builder b(params, progress, *temp, *writer);
    if (Status s = b.run(source); !s) return s.error();
    StreamedModel model;
    model.source = params.source;
    model.sourceHash = params.sourceHash;
    model.params = params.subdivision;
    model.nodes = std::move(b.nodes);
    if (Status s = writer->finish(model); !s) return s.error();
    return b.stats;
}

}  // namespace dyncull
