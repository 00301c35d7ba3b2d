// StreamedObjects (streamed_objects.hpp): leaves as bounds-model objects, drawn through the
// engine's draw callback from two residency levels: GL buffers (least recently drawn
// released first) over a LeafCache in main memory.
// Paper: Out-of-core interactive display of large meshes using an oriented bounding
// box-based hardware depth query, section 5 (memory chunks per node, LRU replacement, two
// reserve chunks for a node that finds none free: here a transient upload).
#include "dyncull/engine/streamed_objects.hpp"

#include <algorithm>
#include <cmath>
#include <unordered_map>

#include <epoxy/gl.h>

#include "dyncull/engine/renderer.hpp"

namespace dyncull {

const char* toString(StreamLate late) {
    switch (late) {
        case StreamLate::Wait: return "wait";
        case StreamLate::Draw: return "draw";
        case StreamLate::Skip: return "skip";
    }
    return "?";
}

Expected<StreamLate> parseStreamLate(const std::string& name) {
    if (name == "wait") return StreamLate::Wait;
    if (name == "draw") return StreamLate::Draw;
    if (name == "skip") return StreamLate::Skip;
    return Error{"unknown late-leaf policy '" + name + "' (wait, draw or skip)", ErrorCode::BadArgument};
}

struct StreamedObjects::State {
    Engine& engine;
    StreamingOptions options;
    StreamedModel model;
    std::unique_ptr<LeafCache> cache;
    std::vector<std::uint32_t> leafOfSlot;  // object slot -> leaf (kInvalidIndex: not ours)
    std::vector<ObjectHandle> objectOfLeaf;
    std::optional<GeometryFile> truthFile;     // readLeaf's own handle, opened on first use
    std::vector<unsigned char> truthScratch;
    Mesh expanded;  // the leaf being uploaded, decoded from its compact form

    struct Gpu {
        MeshId mesh = 0;
        bool resident = false;
        std::uint64_t frame = 0;   // last frame it was drawn in
        std::uint64_t inView = 0;  // last frame whose current or predicted frustum held it
        std::size_t bytes = 0;
    };
    std::vector<Gpu> gpu;
    std::vector<std::uint32_t> gpuResident;  // leaves with GL buffers
    std::size_t gpuBytes = 0, peakGpuBytes = 0;
    std::size_t transientBytes = 0;  // transient uploads since the last flush

    std::uint64_t frame = 0;
    std::vector<std::uint32_t> drawn, lastDrawn, urgent, wanted;
    std::vector<std::uint8_t> listed;  // per leaf, while building `wanted`
    std::vector<std::uint32_t> leafOfNode;
    std::optional<Camera> previous;
    StreamingFrameStats frameStats;
    LeafCacheStats cacheAtStart;
    std::optional<Error> error;

    State(Engine& e, const StreamingOptions& o) : engine(e), options(o) {}

    std::size_t gpuBudget() const { return options.gpuBytes ? options.gpuBytes : SIZE_MAX; }

    /// Releases leaves drawn neither this frame nor the last until `bytes` more fit: those
    /// outside this frame's current and predicted frustums first, then the least recently
    /// drawn. Last frame's leaves are kept: most are drawn again later in this frame, and
    /// releasing them for a new leaf would make each frame read them all again when the
    /// budget is smaller than a frame's leaves (the new leaf is drawn from a transient copy
    /// instead).
    bool makeGpuRoom(std::size_t bytes) {
        while (gpuBytes + bytes > gpuBudget()) {
            std::size_t victim = SIZE_MAX;
            for (std::size_t k = 0; k < gpuResident.size(); ++k) {
                const Gpu& g = gpu[gpuResident[k]];
                if (g.frame + 1 >= frame) continue;
                if (victim == SIZE_MAX) {
                    victim = k;
                    continue;
                }
                const Gpu& v = gpu[gpuResident[victim]];
                const bool gInView = g.inView == frame, vInView = v.inView == frame;
                if (gInView != vInView ? vInView : g.frame < v.frame) victim = k;
            }
            if (victim == SIZE_MAX) return false;
            Gpu& g = gpu[gpuResident[victim]];
            engine.renderer().release(g.mesh);
            g.resident = false;
            gpuBytes -= g.bytes;
            gpuResident[victim] = gpuResident.back();
            gpuResident.pop_back();
            ++frameStats.gpuEvictions;
        }
        return true;
    }

    void draw(ObjectHandle object, ModelId modelId, std::uint32_t first, std::uint32_t count, const glm::mat4& m) {
        Renderer& r = engine.renderer();
        const glm::vec3 colour = colourForId(object.index);
        const std::uint32_t leaf = object.index < leafOfSlot.size() ? leafOfSlot[object.index] : kInvalidIndex;
        if (leaf == kInvalidIndex) {  // another object of the engine: drawn as the engine would
            if (engine.meshOf(modelId) != Engine::kNoMesh) r.drawRange(engine.meshOf(modelId), first, count, m, colour);
            return;
        }
        // The leaf's geometry is in world space; `m` places the unit box that stands for it.
        static const glm::mat4 identity(1.0f);
        Gpu& g = gpu[leaf];
        if (g.frame != frame) drawn.push_back(leaf);
        g.frame = frame;
        if (g.resident) {
            r.drawMesh(g.mesh, identity, colour);
            return;
        }
        const CompactLeaf* compact = nullptr;
        if (options.late == StreamLate::Wait) {
            auto got = cache->acquire(leaf);
            if (!got) {
                if (!error) error = got.error();
                return;
            }
            compact = *got;
        } else {
            compact = cache->tryAcquire(leaf);
            if (!compact) {
                ++frameStats.late;
                if (options.late == StreamLate::Draw) urgent.push_back(leaf);
                return;
            }
        }
        expandLeaf(*compact, expanded);
        cache->release(leaf);
        const std::size_t bytes = leafBytes(expanded);
        const bool keep = makeGpuRoom(bytes);
        auto uploaded = r.upload(expanded, FaceMode::TwoSided);
        if (!uploaded) {
            if (!error) error = uploaded.error();
            return;
        }
        ++frameStats.uploads;
        r.drawMesh(*uploaded, identity, colour);
        if (!keep) {  // the GL budget is full of this frame's leaves: draw from a transient copy
            r.release(*uploaded);
            ++frameStats.overflow;
            // A released buffer lives on until the draws using it have run: flushing now and
            // then bounds the transient copies to a quarter of the budget (or 8 MB).
            transientBytes += bytes;
            if (transientBytes > std::max<std::size_t>(options.gpuBytes / 4, std::size_t{8} << 20)) {
                glFlush();
                transientBytes = 0;
            }
            return;
        }
        g.mesh = *uploaded;
        g.resident = true;
        g.bytes = bytes;
        gpuBytes += bytes;
        peakGpuBytes = std::max(peakGpuBytes, gpuBytes);
        gpuResident.push_back(leaf);
    }

    void want(std::uint32_t leaf) {
        if (listed[leaf]) return;
        listed[leaf] = 1;
        wanted.push_back(leaf);
    }
};

StreamedObjects::StreamedObjects(std::unique_ptr<State> s) : s_(std::move(s)) {}

StreamedObjects::~StreamedObjects() = default;

void StreamedObjects::detach() {
    State& s = *s_;
    s.engine.setDrawCallback(nullptr);
    for (std::uint32_t leaf : s.gpuResident) {
        s.engine.renderer().release(s.gpu[leaf].mesh);
        s.gpu[leaf].resident = false;
    }
    s.gpuResident.clear();
    s.gpuBytes = 0;
}

Expected<std::unique_ptr<StreamedObjects>> StreamedObjects::create(Engine& engine, const std::filesystem::path& nodePath,
                                                                   const StreamingOptions& options) {
    if (!engine.hasRenderer())
        return Error{"streamed objects are drawn by the part renderer (EngineOptions::partRenderer)", ErrorCode::BadArgument};
    if (!(options.widenFov >= 1.0f) || !std::isfinite(options.widenFov))
        return Error{"widenFov must be at least 1", ErrorCode::BadArgument};
    auto model = readStreamedModel(nodePath);
    if (!model) return model.error();
    auto s = std::make_unique<State>(engine, options);
    s->model = model.take();
    std::size_t total = 0, largest = 0;  // main memory keeps leaves compact, GL buffers expanded
    for (const StreamedLeaf& l : s->model.leaves) {
        total += compactLeafBytes(l);
        largest = std::max(largest, leafBytes(l));
    }
    if (options.gpuBytes && largest > options.gpuBytes)
        return Error{nodePath.string() + ": its largest leaf needs " + std::to_string((largest >> 20) + 1) +
                         " MB of GL buffers, more than the whole GPU budget of " + std::to_string(options.gpuBytes >> 20) +
                         " MB",
                     ErrorCode::BadArgument};
    auto cache = LeafCache::create(s->model, options.memoryBytes ? options.memoryBytes : total);
    if (!cache) return cache.error();
    s->cache = cache.take();
    const auto n = static_cast<std::uint32_t>(s->model.leaves.size());
    s->gpu.resize(n);
    s->listed.assign(n, 0);
    s->leafOfNode.assign(s->model.nodes.size(), kInvalidIndex);
    for (std::uint32_t i = 0; i < n; ++i) s->leafOfNode[s->model.leaves[i].node] = i;
    s->objectOfLeaf.resize(n);
    // One unit-box model per triangle count, placed and sized by each object's transform:
    // tens of thousands of leaves share a few hundred models (each model holds volumes,
    // clusters and a tree), and the cost model still sees every leaf's own triangles.
    std::unordered_map<std::uint32_t, ModelId> boxOfCount;
    for (std::uint32_t i = 0; i < n; ++i) {
        const StreamedLeaf& l = s->model.leaves[i];
        auto found = boxOfCount.find(l.triangleCount);
        if (found == boxOfCount.end()) {
            auto id = engine.addBoundsModel(Aabb::fromMinMax(glm::vec3(0.0f), glm::vec3(1.0f)), l.triangleCount, false);
            if (!id) return id.error();
            found = boxOfCount.emplace(l.triangleCount, *id).first;
        }
        // Grown by a relative 1e-6 (a few float ulps at these magnitudes) so min + scale
        // rounding can never pull a face inside the leaf; a flat leaf gets that thickness.
        const glm::vec3 extent = l.box.max - l.box.min;
        const float pad = 1e-6f * (glm::length(l.box.min) + glm::length(l.box.max) + glm::length(extent)) + 1e-30f;
        Transform t;
        t.translation = l.box.min - glm::vec3(pad);
        t.scale = extent + glm::vec3(2.0f * pad);
        auto object = engine.addObject(found->second, t, true);
        if (!object) return object.error();
        if (s->leafOfSlot.size() <= object->index) s->leafOfSlot.resize(object->index + 1, kInvalidIndex);
        s->leafOfSlot[object->index] = i;
        s->objectOfLeaf[i] = *object;
    }
    if (options.memoryBytes == 0) {  // in core: every leaf now, read by the loader thread
        std::vector<std::uint32_t> all(n);
        for (std::uint32_t i = 0; i < n; ++i) all[i] = i;
        s->cache->prefetch(all);
        s->cache->drain();
    }
    State* st = s.get();
    engine.setDrawCallback([st](ObjectHandle object, ModelId modelId, std::uint32_t first, std::uint32_t count,
                                const glm::mat4& m) { st->draw(object, modelId, first, count, m); });
    s->cacheAtStart = s->cache->stats();
    return std::unique_ptr<StreamedObjects>(new StreamedObjects(std::move(s)));
}

void StreamedObjects::beginFrame(const Camera& camera) {
    State& s = *s_;
    ++s.frame;
    s.frameStats = StreamingFrameStats{};
    s.cacheAtStart = s.cache->stats();
    s.error.reset();
    if (s.options.memoryBytes == 0) return;  // in core: everything is resident

    // The camera moved on by its last motion, seeing wider: what the next frames may show.
    Camera predicted = camera;
    if (s.previous) {
        const glm::vec3 motion = camera.position - s.previous->position;
        predicted.position += motion;
        predicted.target += motion;
    }
    predicted.fovYRadians = std::min(camera.fovYRadians * s.options.widenFov, 2.8f);
    s.previous = camera;
    const Frustum now = Frustum::fromCamera(camera), next = Frustum::fromCamera(predicted);

    // A leaf kept in GL buffers is drawn from there: main memory is for the others.
    // Last frame's drawn leaves first (drawn again, mostly), then the leaves in either
    // frustum, found through the tree (a subtree outside both is skipped), soonest to show
    // first by a guess in pixels of view motion: how far the leaf lay from showing in the
    // culler's newest depth pyramid (a hidden leaf shows when a silhouette in front of it
    // moves across it), plus a few pixels for every frame since the culler last saw it
    // (what the camera passes shows again); ties nearest first. The weights were fitted on
    // the plant flythrough's logged candidates (docs/BENCHMARKS.md, out of core).
    constexpr int kMaxSlack = 64;               // pixels; a leaf further counts twice that
    constexpr float kOffScreenSlack = 16.0f;    // off the pyramid's screen, or no pyramid
    constexpr float kSlackPerFrame = 4.0f;      // per frame since last visible
    constexpr std::uint32_t kMaxAge = 64;       // frames; never visible counts this
    s.wanted.clear();
    for (std::uint32_t leaf : s.urgent) s.want(leaf);
    for (std::uint32_t leaf : s.lastDrawn)
        if (!s.gpu[leaf].resident) s.want(leaf);
    struct Near {
        float score;  // pixels of view motion before it shows: smaller first
        float distance;
        std::uint32_t leaf;
    };
    const QueryScheduler& culler = s.engine.scheduler();
    std::vector<Near> found;
    std::vector<std::uint32_t> stack{0};
    while (!stack.empty()) {
        const std::uint32_t k = stack.back();
        stack.pop_back();
        const SubdivisionNode& node = s.model.nodes[k];
        if (node.triangleCount == 0 || (now.outside(node.box) && next.outside(node.box))) continue;
        if (!node.isLeaf()) {
            for (std::uint32_t c = 0; c < node.childCount; ++c) stack.push_back(node.firstChild + c);
            continue;
        }
        // A leaf in GL buffers is left out only if it was drawn last frame, which keeps it
        // there through this one (makeGpuRoom); any other may be released for this frame's
        // leaves and then be drawn from main memory.
        const std::uint32_t leaf = s.leafOfNode[k];
        s.gpu[leaf].inView = s.frame;
        if (s.gpu[leaf].resident && s.gpu[leaf].frame + 1 >= s.frame) continue;
        const NodeHistory* h = culler.history(NodeRef{s.objectOfLeaf[leaf].index, 0}, s.engine.objects());
        const std::uint32_t age = h && h->lastVisibleFrame ? std::min(culler.frameIndex() - h->lastVisibleFrame, kMaxAge) : kMaxAge;
        const std::optional<float> slack = culler.pixelsFromShowing(node.box, kMaxSlack);
        const float pixels = !slack ? kOffScreenSlack : std::min(*slack, 2.0f * float(kMaxSlack));
        const glm::vec3 nearest = glm::clamp(camera.position, node.box.min, node.box.max);
        found.push_back({pixels + kSlackPerFrame * float(age), glm::distance(nearest, camera.position), leaf});
    }
    std::sort(found.begin(), found.end(), [](const Near& a, const Near& b) {
        return a.score != b.score ? a.score < b.score : a.distance < b.distance;
    });
    for (const Near& f : found) s.want(f.leaf);
    for (std::uint32_t leaf : s.wanted) s.listed[leaf] = 0;
    s.urgent.clear();
    s.cache->prefetch(s.wanted);
}

Expected<StreamingFrameStats> StreamedObjects::endFrame() {
    State& s = *s_;
    s.lastDrawn.swap(s.drawn);
    s.drawn.clear();
    const LeafCacheStats now = s.cache->stats();
    StreamingFrameStats& f = s.frameStats;
    f.memoryResidentBytes = now.residentBytes;
    f.gpuResidentBytes = s.gpuBytes;
    f.bytesRead = now.bytesRead - s.cacheAtStart.bytesRead;
    f.loads = now.loads - s.cacheAtStart.loads;
    f.evictions = now.evictions - s.cacheAtStart.evictions;
    f.hits = now.hits - s.cacheAtStart.hits;
    f.misses = now.misses - s.cacheAtStart.misses;
    f.stallMs = now.stallMs - s.cacheAtStart.stallMs;
    if (s.error) return *s.error;
    return f;
}

void StreamedObjects::setLate(StreamLate late) { s_->options.late = late; }

const StreamedModel& StreamedObjects::model() const { return s_->model; }

std::optional<std::uint32_t> StreamedObjects::leafOf(ObjectHandle object) const {
    if (object.index >= s_->leafOfSlot.size() || s_->leafOfSlot[object.index] == kInvalidIndex) return std::nullopt;
    const std::uint32_t leaf = s_->leafOfSlot[object.index];
    if (!(s_->objectOfLeaf[leaf] == object)) return std::nullopt;
    return leaf;
}

std::optional<std::uint32_t> StreamedObjects::leafOfSlot(std::uint32_t slot) const {
    if (slot >= s_->leafOfSlot.size() || s_->leafOfSlot[slot] == kInvalidIndex) return std::nullopt;
    return s_->leafOfSlot[slot];
}

Status StreamedObjects::readLeaf(std::uint32_t leaf, Mesh& out) const {
    if (!s_->truthFile) {
        auto file = GeometryFile::open(s_->model);
        if (!file) return file.error();
        s_->truthFile.emplace(file.take());
    }
    // What the draws show: the leaf through its compact form.
    CompactLeaf compact;
    if (Status st = s_->truthFile->readCompact(leaf, compact, out, s_->truthScratch); !st) return st;
    expandLeaf(compact, out);
    return {};
}

const LeafCacheStats StreamedObjects::cacheStats() const { return s_->cache->stats(); }
std::size_t StreamedObjects::peakGpuBytes() const { return s_->peakGpuBytes; }

}  // namespace dyncull
