#include "dyncull/engine/engine.hpp"

#include <cassert>
#include <chrono>
#include <string>

#include <epoxy/gl.h>

#include "gl_state_scope.hpp"
#include "part_marks.hpp"

namespace dyncull {

// Records every part in the view's visible lists, then draws it (the game's callback or
// the part renderer). With the part renderer it also tests parts on their own triangles.
struct Engine::Sink final : PartSink {
    Engine& e;
    VisibleLists& visible;
    bool marking = false;        // every draw marks one slot (beginDrawMarks)
    bool markingRanges = false;  // every range of drawPartRanges and drawMorePartRanges marks one (beginRangeMarks)
    std::uint64_t unsubmitted = 0;  // triangles drawn since the last glFlush (EngineOptions::submitTriangles)
    std::uint32_t submits = 0;
    Sink(Engine& engine, VisibleLists& lists) : e(engine), visible(lists) {}
    // Hands what is drawn so far to the GPU once enough has piled up; never waits.
    void drew(std::uint64_t triangles) {
        unsubmitted += triangles;
        if (e.submitTriangles_ == 0 || unsubmitted < e.submitTriangles_) return;
        glFlush();
        unsubmitted = 0;
        ++submits;
    }
    void record(NodeRef part, std::uint32_t firstIndex, std::uint32_t indexCount) {
        const SceneObjects& objs = e.objects_;
        const std::uint32_t object = part.object;
        const ObjectHandle handle = objs.handle(object);
        visible.parts.push_back({handle, part, firstIndex, indexCount});
        if (visible.stamp[object] != visible.serial) {
            visible.stamp[object] = visible.serial;
            visible.objects.push_back(handle);
        }
    }
    void drawPart(NodeRef part, std::uint32_t firstIndex, std::uint32_t indexCount) override {
        record(part, firstIndex, indexCount);
        if (e.callback_) {
            const SceneObjects& objs = e.objects_;
            e.callback_(objs.handle(part.object), objs.modelOf(part.object), firstIndex, indexCount, objs.matrix(part.object));
            drew(indexCount / 3);
            return;
        }
        const IndexRange range{firstIndex, indexCount};
        render(part, {&range, 1}, false);
    }
    bool drawsRanges() const override { return !e.callback_ && e.renderer_; }
    bool cullsBackFaces() const override { return !e.callback_ && e.renderer_ && e.renderer_->backFaceCulling(); }
    void drawPartRanges(NodeRef part, std::span<const IndexRange> ranges) override {
        assert(drawsRanges() && !ranges.empty());
        // The part is visible as a whole: the game's lists get its whole range.
        const LocalBspNode& n = e.objects_.model(e.objects_.modelOf(part.object)).nodes[part.node];
        record(part, n.firstIndex, n.indexCount);
        render(part, ranges, markingRanges);
    }
    void drawMorePartRanges(NodeRef part, std::span<const IndexRange> ranges) override { render(part, ranges, markingRanges); }
    // The part renderer's draw of `ranges` of `part`: one mark for the draw while marking
    // draws, one per range if `markEachRange`.
    void render(NodeRef part, std::span<const IndexRange> ranges, bool markEachRange) {
        const SceneObjects& objs = e.objects_;
        const std::uint32_t object = part.object;
        const std::uint32_t slots = marking ? 1u : markEachRange ? static_cast<std::uint32_t>(ranges.size()) : 0u;
        const MeshId mesh = e.meshOfModel_[objs.modelOf(object)];
        if (mesh == kNoMesh) {  // a bounds model only the draw callback draws
            if (slots > 0) e.marks_->skipDrawSlots(slots);
            return;
        }
        const glm::vec3 colour = object < e.hasColour_.size() && e.hasColour_[object] ? e.colour_[object] : colourForId(object);
        const std::uint32_t markSlot = slots > 0 ? e.marks_->nextDrawSlots(slots) : Renderer::kNoMark;
        // An occludee-only object occludes nothing: drawn without depth writes (after
        // everything that occludes, as the scheduler orders it).
        const bool occludee = objs.role(object) == OcclusionRole::OccludeeOnly;
        if (occludee) glDepthMask(GL_FALSE);
        if (ranges.size() == 1)
            e.renderer_->drawRange(mesh, ranges[0].firstIndex, ranges[0].indexCount, objs.matrix(object), colour, markSlot);
        else
            e.renderer_->drawRanges(mesh, ranges, objs.matrix(object), colour, markSlot, markEachRange && markSlot != Renderer::kNoMark);
        if (occludee) glDepthMask(GL_TRUE);
        std::uint64_t triangles = 0;
        for (const IndexRange& r : ranges) triangles += r.indexCount / 3;
        drew(triangles);
    }
    bool testsTriangles() const override { return !e.callback_ && e.renderer_ && e.marks_; }
    void beginDrawMarks() override {
        assert(testsTriangles());
        e.marks_->beginDraws();
        marking = true;
    }
    void readDrawMarks(std::span<QueryResult> out) override {
        assert(marking && out.size() == e.marks_->drawCount());
        e.marks_->readDraws(out);
    }
    bool marksRanges() const override { return drawsRanges() && e.marks_ && e.renderer_->supportsRangeMarks(); }
    void beginRangeMarks() override {
        assert(marksRanges() && !marking);
        e.marks_->beginDraws();
        markingRanges = true;
    }
    void readRangeMarks(std::span<QueryResult> out) override {
        assert(markingRanges && out.size() == e.marks_->drawCount());
        e.marks_->readDraws(out);
        markingRanges = false;
    }
    void testParts(std::span<const PartRange> parts, std::span<QueryResult> out) override {
        assert(testsTriangles() && out.size() == parts.size());
        if (!e.marks_->beginTest(static_cast<std::uint32_t>(parts.size()))) {
            std::fill(out.begin(), out.end(), QueryResult::Visible);  // no buffer: test nothing
            return;
        }
        // Writes off: the test draws nothing into the image.
        glColorMask(GL_FALSE, GL_FALSE, GL_FALSE, GL_FALSE);
        glDepthMask(GL_FALSE);
        const SceneObjects& objs = e.objects_;
        for (std::uint32_t i = 0; i < parts.size(); ++i) {
            const std::uint32_t object = parts[i].part.object;
            const MeshId mesh = e.meshOfModel_[objs.modelOf(object)];
            if (mesh != kNoMesh)
                e.renderer_->testRange(mesh, parts[i].firstIndex, parts[i].indexCount, objs.matrix(object), i);
        }
        glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
        glDepthMask(GL_TRUE);
        e.marks_->endTest();
        e.marks_->readTest(out);
        for (std::uint32_t i = 0; i < parts.size(); ++i)  // nothing to test: visible, as it must be
            if (e.meshOfModel_[objs.modelOf(parts[i].part.object)] == kNoMesh) out[i] = QueryResult::Visible;
    }
};

Engine::Engine(GlContext& context, const EngineOptions& options)
    : context_(context), tree_(options.sceneTree), finishEachFrame_(options.finishEachFrame), submitTriangles_(options.submitTriangles) {
    View& main = views_.emplace_back();
    main.scheduler = std::make_unique<QueryScheduler>(options.scheduler);
}

Engine::~Engine() = default;

void Engine::VisibleLists::begin(std::uint32_t slots) {
    if (++serial == 0) {  // wrapped after 2^32 frames: no slot may look drawn this frame
        std::fill(stamp.begin(), stamp.end(), 0u);
        serial = 1;
    }
    stamp.resize(slots, 0);
    parts.clear();
    objects.clear();
}

Engine::View* Engine::findView(ViewId id) { return id < views_.size() && views_[id].live ? &views_[id] : nullptr; }
const Engine::View* Engine::findView(ViewId id) const {
    return id < views_.size() && views_[id].live ? &views_[id] : nullptr;
}

namespace {
Error unknownView(const char* what, ViewId id) {
    return Error{std::string(what) + ": unknown or removed view " + std::to_string(id)};
}
}  // namespace

Expected<ViewId> Engine::addView(const Camera& camera, const SchedulerParams& params) {
    if (Status s = validateCamera(camera); !s) return s.error();
    if (Status s = validateSchedulerParams(params); !s) return s.error();
    View& v = views_.emplace_back();
    v.camera = camera;
    v.scheduler = std::make_unique<QueryScheduler>(params);
    return static_cast<ViewId>(views_.size() - 1);
}

Status Engine::removeView(ViewId id) {
    if (id == kMainView) return Error{"removeView: the main view cannot be removed"};
    View* v = findView(id);
    if (!v) return unknownView("removeView", id);
    *v = View{};
    v->live = false;  // ids are never reused, so a stale id stays an error
    return {};
}

std::span<const VisiblePart> Engine::visibleParts(ViewId view) const {
    const View* v = findView(view);
    return v ? std::span<const VisiblePart>(v->visible.parts) : std::span<const VisiblePart>();
}

std::span<const ObjectHandle> Engine::visibleObjects(ViewId view) const {
    const View* v = findView(view);
    return v ? std::span<const ObjectHandle>(v->visible.objects) : std::span<const ObjectHandle>();
}

bool Engine::isVisible(ObjectHandle object, ViewId view) const {
    const View* v = findView(view);
    return v && objects_.alive(object) && object.index < v->visible.stamp.size() &&
           v->visible.stamp[object.index] == v->visible.serial;
}

const Camera& Engine::camera(ViewId view) const {
    const View* v = findView(view);
    return v ? v->camera : views_[kMainView].camera;
}

QueryScheduler& Engine::scheduler(ViewId view) {
    View* v = findView(view);
    return *(v ? v : &views_[kMainView])->scheduler;
}

Status Engine::enterGl(const char* what) {
    if (Status s = context_.checkCurrent(what); !s) return s;
    if (Status s = context_.checkReset(); !s) return s;
    callerGlErrors_ += context_.takeCallerErrors();
    return {};
}

Status Engine::checkDrawer(const char* what) const {
    if (renderer_ || callback_) return {};
    return Error{std::string(what) + ": no draw callback, and the part renderer is off (EngineOptions::partRenderer)"};
}

Status Engine::leaveGl(const char* what) {
    if (Status s = context_.checkReset(); !s) return s;
    return context_.checkErrorsDuring(what);
}

Expected<std::unique_ptr<Engine>> Engine::create(GlContext& context, const EngineOptions& options) {
    if (Status s = validateSchedulerParams(options.scheduler); !s) return s.error();
    std::unique_ptr<Engine> e(new Engine(context, options));
    if (Status s = e->enterGl("creating the engine"); !s) return s.error();
    if (options.partRenderer) {
        auto renderer = Renderer::create(context);
        if (!renderer) return renderer.error();
        e->renderer_ = renderer.take();
        e->marks_ = std::make_unique<detail::PartMarks>(context);
    }
    auto backend = GlQueryBackend::create(context, options.queries);
    if (!backend) return backend.error();
    e->backend_ = backend.take();
    if (Status s = e->leaveGl("creating the engine"); !s) return s.error();
    const glm::ivec2 size = context.size();
    e->views_[kMainView].camera.aspect = static_cast<float>(size.x) / static_cast<float>(size.y);
    return e;
}

Expected<ModelId> Engine::addModel(const Mesh& mesh, const LocalBspParams& params) {
    auto bsp = buildLocalBsp(mesh, params);
    if (!bsp) return bsp.error();
    return addModel(bsp.take());
}

Expected<ModelId> Engine::addBoundsModel(const Aabb& bounds, std::uint32_t triangles, bool uploadBox) {
    auto bsp = buildBoundsModel(bounds, triangles);
    if (!bsp) return bsp.error();
    return addModel(bsp.take(), uploadBox);
}

Expected<ModelId> Engine::addModel(LocalBsp bsp) { return addModel(std::move(bsp), true); }

Expected<ModelId> Engine::addModel(LocalBsp bsp, bool upload) {
    if (Status s = enterGl("adding a model"); !s) return s.error();
    // Upload first: if the GPU refuses, nothing has been registered yet.
    MeshId mesh = kNoMesh;
    if (renderer_ && upload) {
        auto uploaded = renderer_->upload(bsp.mesh, bsp.faces);
        if (!uploaded) return uploaded.error();
        mesh = *uploaded;
    }
    if (Status s = leaveGl("adding a model"); !s) return s.error();
    const ModelId id = objects_.addModel(std::move(bsp));
    if (meshOfModel_.size() <= id) meshOfModel_.resize(id + 1);
    meshOfModel_[id] = mesh;
    return id;
}

Expected<ObjectHandle> Engine::addObject(ModelId model, const Transform& transform, bool isStatic) {
    return objects_.addObject(model, transform, isStatic);
}

Status Engine::setRole(ObjectHandle object, OcclusionRole role) { return objects_.setRole(object, role); }

Status Engine::removeObject(ObjectHandle object) {
    if (Status s = objects_.removeObject(object); !s) return s;
    if (object.index < hasColour_.size()) hasColour_[object.index] = 0;  // the next object of the slot starts afresh
    return {};
}

Status Engine::removeModel(ModelId model) {
    if (renderer_) {
        if (Status s = enterGl("removeModel"); !s) return s;
    }
    if (Status s = objects_.removeModel(model); !s) return s;
    if (renderer_) {
        if (meshOfModel_[model] != kNoMesh) renderer_->release(meshOfModel_[model]);
        if (Status s = leaveGl("removeModel"); !s) return s;
    }
    return {};
}

Expected<ObjectHandle> Engine::setModel(ObjectHandle object, ModelId model) {
    return objects_.setModel(object, model);  // same slot, so the object keeps its colour
}

Status Engine::setTransform(ObjectHandle object, const Transform& transform) {
    return objects_.setTransform(object, transform);
}

Status Engine::setCamera(ViewId view, const Camera& camera) {
    View* v = findView(view);
    if (!v) return unknownView("setCamera", view);
    if (Status s = validateCamera(camera); !s) return s;
    v->camera = camera;
    return {};
}

Status Engine::setSchedulerParams(ViewId view, const SchedulerParams& params) {
    View* v = findView(view);
    if (!v) return unknownView("setSchedulerParams", view);
    if (Status s = validateSchedulerParams(params); !s) return s;
    v->scheduler->setParams(params);
    return {};
}

void Engine::setColour(ObjectHandle object, const glm::vec3& colour) {
    if (!objects_.alive(object)) return;
    if (colour_.size() <= object.index) {
        colour_.resize(object.index + 1);
        hasColour_.resize(object.index + 1, 0);
    }
    colour_[object.index] = colour;
    hasColour_[object.index] = 1;
}

LooseBspFrameStats Engine::updateSceneTree() {
    if (!treeBuilt_) {
        const auto t0 = std::chrono::steady_clock::now();
        tree_.build(objects_);
        treeBuilt_ = true;
        LooseBspFrameStats st;
        st.updateMs = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
        return st;
    }
    return tree_.update(objects_);
}

Expected<FrameStats> Engine::renderView(ViewId id) {
    View* v = findView(id);
    if (!v) return unknownView("renderView", id);
    return cullAndDraw(*v, *v->scheduler);
}

Expected<FrameStats> Engine::renderFrame(QueryScheduler& scheduler) { return cullAndDraw(views_[kMainView], scheduler); }

template <class Draw>
Expected<FrameStats> Engine::drawFrame(View& view, const char* what, Draw draw) {
    view.visible.begin(objects_.slotCount());  // a refused frame draws nothing
    if (Status s = checkDrawer(what); !s) return s.error();
    if (Status s = enterGl(what); !s) return s.error();
    using Clock = std::chrono::steady_clock;
    const auto t0 = Clock::now();
    const double updateMs = updateSceneTree().updateMs;  // once per frame: later views find nothing moved

    detail::GlStateScope scope;
    const FrameTarget& target = scope.target();
    backend_->setTarget(target);
    // The frame's view, derived once for the renderer, the scheduler and the query backend.
    const FrameView frame = FrameView::of(view.camera, target.width(), target.height());
    if (renderer_) renderer_->beginFrame(frame);
    Sink sink(*this, view.visible);
    FrameStats st = draw(frame, sink);
    st.drawSubmits = sink.submits;
    if (renderer_) renderer_->endFrame();
    if (finishEachFrame_) glFinish();
    scope.restore();
    // A reset during the frame: its image and query results are undefined, so report it.
    if (Status s = leaveGl(what); !s) return s.error();
    if (!backend_->frameStatus()) return backend_->frameStatus().error();
    st.updateMs = updateMs;
    st.frameMs = std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
    return st;
}

Expected<FrameStats> Engine::cullAndDraw(View& view, QueryScheduler& scheduler) {
    return drawFrame(view, "renderFrame", [&](const FrameView& frame, Sink& sink) {
        TwoLevelTree tree(tree_, objects_);
        return scheduler.cullFrame(tree, frame, *backend_, sink);
    });
}

Expected<FrameStats> Engine::renderParts(const std::vector<NodeRef>& parts) {
    std::vector<PartRange> whole;
    whole.reserve(parts.size());
    for (const NodeRef& ref : parts) {
        assert(!ref.isSceneNode() && ref.object < objects_.slotCount() && objects_.alive(ref.object));
        const LocalBsp& bsp = objects_.model(objects_.modelOf(ref.object));
        assert(ref.node < bsp.nodes.size());
        whole.push_back({ref, bsp.nodes[ref.node].firstIndex, bsp.nodes[ref.node].indexCount});
    }
    return renderPartRanges(whole);
}

Expected<FrameStats> Engine::renderPartRanges(std::span<const PartRange> ranges) {
    return drawFrame(views_[kMainView], "renderPartRanges", [&](const FrameView&, Sink& sink) {
        FrameStats st;
        const auto tDraw = std::chrono::steady_clock::now();
        std::vector<IndexRange> partRanges;
        for (std::size_t i = 0; i < ranges.size();) {
            const NodeRef ref = ranges[i].part;
            assert(!ref.isSceneNode() && ref.object < objects_.slotCount() && objects_.alive(ref.object));
            partRanges.clear();
            for (; i < ranges.size() && ranges[i].part == ref; ++i) partRanges.push_back({ranges[i].firstIndex, ranges[i].indexCount});
            const LocalBspNode& n = objects_.model(objects_.modelOf(ref.object)).nodes[ref.node];
            if (sink.drawsRanges()) {
                sink.drawPartRanges(ref, partRanges);
                for (const IndexRange& r : partRanges) st.trianglesDrawn += r.indexCount / 3;
            } else {
                // A game's draw callback gets whole parts, as in renderFrame.
                sink.drawPart(ref, n.firstIndex, n.indexCount);
                st.trianglesDrawn += n.indexCount / 3;
            }
            ++st.partsDrawn;
        }
        st.drawMs = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - tDraw).count();
        st.nodesVisited = st.partsDrawn;
        return st;
    });
}

}  // namespace dyncull
