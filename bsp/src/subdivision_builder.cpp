// Builds a subdivision hierarchy with any method (subdivide_*.cpp): recursion, node layout
// (children contiguous, after their parent), subtrees on worker threads, bottom-up boxes.
// Paper: Scene subdivision for occlusion culling, section 3 (subdivision entities; the
// termination parameters Max_Triangles_Per_Subdivision_Entity and Max_Subdivision_Depth)
// and section 4 ("we removed redundant tree nodes": single-child chains are skipped).
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <future>
#include <numeric>
#include <thread>

#include "subdivision_builder.hpp"

namespace dyncull {
namespace detail {

void computeSoupData(const Mesh& mesh, unsigned threads, SoupData& soup) {
    const std::size_t n = mesh.triangleCount();
    soup.centroid.resize(n);
    soup.box.resize(n);
    auto work = [&](std::size_t begin, std::size_t end) {
        for (std::size_t t = begin; t < end; ++t) {
            const glm::vec3 a = mesh.positions[mesh.indices[3 * t]], b = mesh.positions[mesh.indices[3 * t + 1]],
                            c = mesh.positions[mesh.indices[3 * t + 2]];
            soup.centroid[t] = (a + b + c) * (1.0f / 3.0f);
            soup.box[t] = Aabb::fromMinMax(glm::min(a, glm::min(b, c)), glm::max(a, glm::max(b, c)));
        }
    };
    threads = std::max(1u, std::min<unsigned>(threads, static_cast<unsigned>(n / 65536 + 1)));
    std::vector<std::thread> pool;
    for (unsigned i = 1; i < threads; ++i) pool.emplace_back(work, n * i / threads, n * (i + 1) / threads);
    work(0, n / threads);
    for (std::thread& t : pool) t.join();
}

void splitInHalf(std::span<std::uint32_t> tris, std::vector<ChildPart>& out) {
    const auto half = static_cast<std::uint32_t>(tris.size() / 2);
    out.push_back({half, {}});
    out.push_back({static_cast<std::uint32_t>(tris.size()) - half, {}});
}

namespace {

/// Nodes of one subtree; [0] is its root, child indices are local to the fragment.
using Fragment = std::vector<SubdivisionNode>;

/// Subtrees above this many triangles build their children as separate fragments that
/// may run on another thread. A constant, so the layout never depends on thread count.
constexpr std::uint32_t kParallelGrain = 1u << 16;

class Builder {
public:
    Builder(const SoupData& soup, const SubdivisionParams& p, std::vector<std::uint32_t>& tris)
        : soup_(soup), p_(p), tris_(tris), freeThreads_(static_cast<int>(p.threads) - 1) {}

    Fragment build(std::uint32_t first, std::uint32_t count, const Aabb& cell, std::uint32_t depth) {
        std::unique_ptr<Splitter> splitter = makeSplitter();
        Fragment f;
        f.push_back({});
        f[0].firstTriangle = first;
        f[0].triangleCount = count;
        f[0].depth = depth;
        std::vector<ChildPart> parts;
        // Cells of nodes still to split, by node index (only the regular octree uses them).
        struct Open {
            std::uint32_t node;
            Aabb cell;
        };
        std::vector<Open> stack{{0, cell}};
        while (!stack.empty()) {
            const Open open = stack.back();
            stack.pop_back();
            std::uint32_t d = f[open.node].depth;
            Aabb c = open.cell;
            const std::uint32_t nFirst = f[open.node].firstTriangle, nCount = f[open.node].triangleCount;
            // Follow single-child splits (the regular octree's empty octants) without nodes.
            for (;;) {
                parts.clear();
                if (nCount <= p_.maxLeafTriangles || d >= p_.maxDepth) break;
                splitter->split(std::span<std::uint32_t>(tris_.data() + nFirst, nCount), c, d, parts);
                if (parts.size() != 1) break;
                if (parts[0].cell.min == c.min && parts[0].cell.max == c.max) {
                    // A cell that cannot shrink (all barycentres at one point): halve the
                    // list so the triangle limit still holds.
                    parts.clear();
                    splitInHalf(std::span<std::uint32_t>(tris_.data() + nFirst, nCount), parts);
                    for (ChildPart& part : parts) part.cell = c;
                    break;
                }
                c = parts[0].cell;
                ++d;
            }
            f[open.node].depth = d;
            if (parts.size() < 2) continue;  // leaf
            noteScratch(splitter->scratchBytes());
            if (nCount > kParallelGrain && open.node == 0 && f.size() == 1) {
                splitLarge(f, parts, d);
                return f;
            }
            const auto firstChild = static_cast<std::uint32_t>(f.size());
            f[open.node].firstChild = firstChild;
            f[open.node].childCount = static_cast<std::uint32_t>(parts.size());
            std::uint32_t at = nFirst;
            for (const ChildPart& part : parts) {
                SubdivisionNode child;
                child.firstTriangle = at;
                child.triangleCount = part.count;
                child.depth = d + 1;
                at += part.count;
                f.push_back(child);
            }
            // Push in reverse so the first child is laid out first (depth-first order).
            for (std::size_t i = parts.size(); i-- > 0;)
                stack.push_back({firstChild + static_cast<std::uint32_t>(i), parts[i].cell});
        }
        return f;
    }

    std::size_t peakScratch() const { return peakScratch_.load(); }

private:
    std::unique_ptr<Splitter> makeSplitter() const {
        switch (p_.method) {
            case SubdivisionMethod::Phbvo: return makePhbvoSplitter(soup_, p_);
            case SubdivisionMethod::Dbvs: return makeDbvsSplitter(soup_, p_);
            case SubdivisionMethod::Octree: return makeOctreeSplitter(soup_, p_);
            case SubdivisionMethod::Grid: return makeGridSplitter(soup_, p_);
        }
        return makePhbvoSplitter(soup_, p_);
    }

    void noteScratch(std::size_t bytes) {
        std::size_t cur = peakScratch_.load();
        while (bytes > cur && !peakScratch_.compare_exchange_weak(cur, bytes)) {
        }
    }

    /// The root of `f` is a large node split into `parts`: build each child as its own
    /// fragment (on a free thread when there is one) and splice them in after the root.
    void splitLarge(Fragment& f, const std::vector<ChildPart>& parts, std::uint32_t depth) {
        const std::size_t k = parts.size();
        std::vector<Fragment> kids(k);
        std::vector<std::future<Fragment>> futures(k);
        std::uint32_t at = f[0].firstTriangle;
        std::vector<std::uint32_t> firsts(k);
        for (std::size_t i = 0; i < k; ++i) {
            firsts[i] = at;
            at += parts[i].count;
        }
        for (std::size_t i = 0; i < k; ++i) {
            // The last child always runs here, so this thread never just waits.
            if (i + 1 < k && freeThreads_.fetch_sub(1) > 0) {
                futures[i] = std::async(std::launch::async, [this, &parts, &firsts, i, depth] {
                    Fragment r = build(firsts[i], parts[i].count, parts[i].cell, depth + 1);
                    freeThreads_.fetch_add(1);
                    return r;
                });
            } else {
                if (i + 1 < k) freeThreads_.fetch_add(1);
                kids[i] = build(firsts[i], parts[i].count, parts[i].cell, depth + 1);
            }
        }
        for (std::size_t i = 0; i < k; ++i)
            if (futures[i].valid()) kids[i] = futures[i].get();
        // Layout: root, the k child roots, then each child's remaining nodes in order.
        f[0].firstChild = 1;
        f[0].childCount = static_cast<std::uint32_t>(k);
        f.resize(1 + k);
        for (std::size_t i = 0; i < k; ++i) {
            const auto base = static_cast<std::uint32_t>(f.size());  // where kids[i][1] lands
            auto remap = [base](SubdivisionNode n) {
                if (!n.isLeaf()) n.firstChild = base + n.firstChild - 1;
                return n;
            };
            f[1 + i] = remap(kids[i][0]);
            for (std::size_t j = 1; j < kids[i].size(); ++j) f.push_back(remap(kids[i][j]));
            Fragment().swap(kids[i]);
        }
    }

    const SoupData& soup_;
    const SubdivisionParams& p_;
    std::vector<std::uint32_t>& tris_;
    std::atomic<int> freeThreads_;
    std::atomic<std::size_t> peakScratch_{0};
};

}  // namespace
}  // namespace detail

const char* toString(SubdivisionMethod m) {
    switch (m) {
        case SubdivisionMethod::Phbvo: return "phbvo";
        case SubdivisionMethod::Dbvs: return "dbvs";
        case SubdivisionMethod::Octree: return "octree";
        case SubdivisionMethod::Grid: return "grid";
    }
    return "?";
}

Expected<SubdivisionMethod> parseSubdivisionMethod(const std::string& name) {
    for (SubdivisionMethod m : {SubdivisionMethod::Phbvo, SubdivisionMethod::Dbvs, SubdivisionMethod::Octree,
                                SubdivisionMethod::Grid})
        if (name == toString(m)) return m;
    return Error{"unknown subdivision method '" + name + "' (expected phbvo, dbvs, octree or grid)"};
}

void recountSubdivisionStats(Subdivision& sub, std::uint32_t maxLeafTriangles) {
    SubdivisionStats& s = sub.stats;
    s.nodes = s.leaves = s.inner = s.depth = s.largestLeaf = s.oversizedLeaves = s.maxChildren = 0;
    s.nodes = static_cast<std::uint32_t>(sub.nodes.size());
    for (const SubdivisionNode& node : sub.nodes) {
        s.maxChildren = std::max(s.maxChildren, node.childCount);
        if (!node.isLeaf()) continue;
        ++s.leaves;
        s.depth = std::max(s.depth, node.depth);
        s.largestLeaf = std::max(s.largestLeaf, node.triangleCount);
        if (node.triangleCount > maxLeafTriangles) ++s.oversizedLeaves;
    }
    s.inner = s.nodes - s.leaves;
}

Status validateSubdivisionParams(const SubdivisionParams& p) {
    if (p.maxLeafTriangles == 0) return Error{"maximum triangles per leaf must be at least 1"};
    if (p.maxDepth > kSubdivisionMaxDepth)
        return Error{"maximum depth " + std::to_string(p.maxDepth) + " above " +
                     std::to_string(kSubdivisionMaxDepth)};
    if (p.sahBins < 2 || p.sahBins > 256) return Error{"SAH bins must be in 2..256"};
    if (!(p.planeMove >= 0.0f && p.planeMove < 0.5f)) return Error{"plane move must be in [0, 0.5)"};
    if (!(p.pullUpWidths >= 0.0f) || !std::isfinite(p.pullUpWidths))
        return Error{"pull-up width must be finite and >= 0"};
    if (p.collapseTo == 1) return Error{"collapse needs at least 2 children per node"};
    if (static_cast<unsigned>(p.method) > 3) return Error{"unknown subdivision method"};
    if (p.threads == 0 || p.threads > 64) return Error{"threads must be in 1..64"};
    return {};
}

Expected<Subdivision> subdivide(const Mesh& mesh, const SubdivisionParams& p) {
    const auto t0 = std::chrono::steady_clock::now();
    if (std::string why = validateMesh(mesh); !why.empty()) return Error{"subdivide: " + why};
    if (Status st = validateSubdivisionParams(p); !st) return Error{"subdivide: " + st.message()};
    const std::size_t n = mesh.triangleCount();
    if (n >= kInvalidIndex) return Error{"subdivide: more than 2^32-2 triangles"};

    Subdivision sub;
    sub.method = p.method;
    detail::SoupData soup;
    detail::computeSoupData(mesh, p.threads, soup);
    sub.triangles.resize(n);
    std::iota(sub.triangles.begin(), sub.triangles.end(), 0u);
    // Root cell: a cube around the barycentres (the regular octree halves it; others ignore it).
    Aabb cb;
    for (const glm::vec3& c : soup.centroid) cb.extend(c);
    Aabb cell;
    if (!cb.empty()) {
        const glm::vec3 e = cb.extent();
        const float half = 0.5f * std::max({e.x, e.y, e.z});
        cell = Aabb::fromMinMax(cb.center() - glm::vec3(half), cb.center() + glm::vec3(half));
    }
    detail::Builder builder(soup, p, sub.triangles);
    sub.nodes = builder.build(0, static_cast<std::uint32_t>(n), cell, 0);

    // Boxes bottom-up: children always come after their parent.
    for (std::size_t i = sub.nodes.size(); i-- > 0;) {
        SubdivisionNode& node = sub.nodes[i];
        node.box = Aabb{};
        if (node.isLeaf()) {
            for (std::uint32_t k = 0; k < node.triangleCount; ++k) node.box.extend(soup.box[sub.triangles[node.firstTriangle + k]]);
        } else {
            for (std::uint32_t c = 0; c < node.childCount; ++c) node.box.extend(sub.nodes[node.firstChild + c].box);
        }
    }
    const std::size_t soupBytes = n * (sizeof(glm::vec3) + sizeof(Aabb) + sizeof(std::uint32_t));
    const std::size_t nodeBytes = sub.nodes.capacity() * sizeof(SubdivisionNode);
    // Splicing holds a child's fragment and its parent's copy at once: count nodes twice.
    sub.stats.workBytes = soupBytes + 2 * nodeBytes + builder.peakScratch() * p.threads;
    std::vector<glm::vec3>().swap(soup.centroid);  // free before the collapse and the caller's copies
    std::vector<Aabb>().swap(soup.box);

    if (p.collapseTo >= 2) collapseSubdivision(sub, p.collapseTo);

    recountSubdivisionStats(sub, p.maxLeafTriangles);
    sub.stats.buildMs = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    return sub;
}

}  // namespace dyncull
