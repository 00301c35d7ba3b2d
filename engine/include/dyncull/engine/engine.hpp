// The API a game calls each frame: add models and objects, update transforms, set the
// camera, then cull and draw. Owns the whole pipeline of one scene:
//   transforms -> loose-BSP relink -> front-to-back traversal -> query scheduler ->
//   query backend -> draw (dyncull's renderer, or the game's callback).
#pragma once

#include <cassert>
#include <functional>
#include <memory>
#include <span>
#include <string>

#include "dyncull/bsp/local_bsp.hpp"
#include "dyncull/bsp/loose_bsp.hpp"
#include "dyncull/bsp/scene_objects.hpp"
#include "dyncull/engine/gl_context.hpp"
#include "dyncull/engine/gl_query_backend.hpp"
#include "dyncull/engine/renderer.hpp"
#include "dyncull/objects/camera.hpp"
#include "dyncull/objects/error.hpp"
#include "dyncull/scheduler/query_scheduler.hpp"

namespace dyncull {

struct EngineOptions {
    LooseBspParams sceneTree;
    SchedulerParams scheduler;
    GlQueryParams queries;
    /// glFinish at the end of every frame, so FrameStats::frameMs bounds the GPU work too
    /// (measurement); off, a frame only submits its work, as a game wants.
    bool finishEachFrame = false;
    /// Drawing is submitted to the GPU (glFlush) after every this many triangles a frame
    /// draws (0: only where the frame reads something back, and at its end). A software
    /// rasteriser such as llvmpipe starts rasterising only at a flush, so without it the
    /// rasteriser idles while the CPU culls and draws, then the CPU idles at the early
    /// pass's depth read. The default is the measured best on llvmpipe (docs/BENCHMARKS.md,
    /// sweep parameter submit-tris). A hardware driver flushes its command buffer by itself
    /// and each glFlush is a submission with its own CPU cost, which was not measured here:
    /// there, start from 0 or a far larger interval.
    std::uint32_t submitTriangles = 4096;
    /// dyncull's own part renderer: addModel uploads each model's split mesh (positions and
    /// normals) to the GPU, and parts are drawn with it unless a draw callback is set. Off,
    /// nothing is uploaded (a game drawing its own buffers keeps one copy) and every frame
    /// needs a draw callback.
    bool partRenderer = true;
};

/// Draws one object part with the game's own renderer: `object` is the handle given by
/// addObject, the range indexes the model's split mesh (Engine::model(id).mesh.indices),
/// and `objectToWorld` is the object's current matrix. A game draws it from its own vertex
/// buffer holding its attributes carried through the split (carryAttributes, local_bsp.hpp)
/// and the split mesh's indices. Called inside renderFrame, into the caller's framebuffer
/// and viewport, with the frame contract's state (frame_contract.hpp): the callback may
/// bind its own program, vertex array, buffers and textures (restored after the frame) and
/// must keep the depth test and reversed-Z convention. An occludee-only object
/// (OcclusionRole, setRole) comes last in the frame and must be drawn without depth writes.
using DrawPartCallback =
    std::function<void(ObjectHandle object, ModelId model, std::uint32_t firstIndex, std::uint32_t indexCount,
                       const glm::mat4& objectToWorld)>;

/// A part drawn in the last frame, which in a conservative mode is every visible part (and
/// perhaps some hidden ones).
struct VisiblePart {
    ObjectHandle object;   ///< the object, as addObject returned it
    NodeRef part;          ///< object slot and local-BSP node: a leaf, or an inner node drawn whole
    std::uint32_t firstIndex = 0;  ///< the node's range of the model's split mesh (Engine::model(id).mesh.indices)
    std::uint32_t indexCount = 0;
};

/// A view of the scene (Engine::addView); the main view, 0, always exists.
using ViewId = std::uint32_t;
inline constexpr ViewId kMainView = 0;

/// Borrows the GL context, which must outlive the Engine (a game's own context is wrapped
/// with GlContext::borrowCurrent). Each frame it draws into the framebuffer and viewport the
/// caller has bound and leaves the caller's GL state as it found it (frame_contract.hpp).
///
/// Views: one scene (objects, models, the loose BSP) is seen by any number of views, each
/// with its own camera, scheduler (mode, parameters, visibility history) and visible lists:
/// split screen, a second camera, a shadow-map pass. Each is drawn by renderView into
/// whatever framebuffer and viewport are bound; the scene tree is relinked once per frame
/// however many views render.
///
/// Threads: an Engine is used from one thread at a time, the one its context is current on;
/// calls that touch GL (create, addModel, renderFrame, renderParts, the destructor) check
/// that the context is current and otherwise fail with ErrorCode::WrongContext (the
/// destructor then deletes no GL object: they die with their own context). Calls that do
/// not touch GL (objects, transforms, camera, parameters) need no context. Two Engines on
/// two contexts may run on two threads.
namespace detail {
class PartMarks;
}

class Engine {
public:
    /// Errors: invalid scheduler parameters, the context not current (WrongContext) or
    /// already lost, shaders rejected by the driver, GPU out of memory for the query volume
    /// buffers.
    static Expected<std::unique_ptr<Engine>> create(GlContext& context, const EngineOptions& options = {});

    /// Builds the model's local BSP (object space) and uploads its split mesh once.
    /// Errors: invalid mesh or parameters, GPU out of memory, context lost; on any error
    /// the engine is exactly as before the call (no model, no buffers).
    Expected<ModelId> addModel(const Mesh& mesh, const LocalBspParams& params = {});
    /// Adds a prebuilt local BSP (e.g. loaded from a cache); errors as above.
    Expected<ModelId> addModel(LocalBsp bsp);
    /// A model the game describes by its object-space bounds only and draws whole when it
    /// is visible (buildBoundsModel: `triangles` is what a draw of it costs, for the cost
    /// model). The draw callback receives the box's index range for it; with the part
    /// renderer the box itself is drawn. Errors: bad bounds or 0 triangles, as addModel.
    /// `uploadBox` false: the part renderer never gets the box (tens of thousands of streamed
    /// leaves would each cost GL buffers for nothing); only the draw callback draws it, and
    /// without one its parts are counted drawn but nothing is drawn.
    Expected<ModelId> addBoundsModel(const Aabb& bounds, std::uint32_t triangles, bool uploadBox = true);
    /// Adds an instance of a model (see SceneObjects::addObject: a static object never moves
    /// and costs nothing per frame).
    Expected<ObjectHandle> addObject(ModelId model, const Transform& transform, bool isStatic = false);
    Status removeObject(ObjectHandle object);
    /// Makes an object occluder-only (never tested, drawn whole and first when in the
    /// frustum) or occludee-only (tested against everything else, drawn whole and last,
    /// without depth writes), or Both again; see OcclusionRole. Error: stale handle.
    Status setRole(ObjectHandle object, OcclusionRole role);
    /// Frees a model no object uses, with its GPU copy (part renderer). To replace a model:
    /// add the new one, move its objects over with setModel, remove the old one.
    /// Errors: unknown or removed model, objects still using it, the context not current.
    Status removeModel(ModelId model);
    /// Gives an object another model; it comes back under a new handle, the old one stale
    /// (SceneObjects::setModel). Errors: stale handle, unknown or removed model.
    Expected<ObjectHandle> setModel(ObjectHandle object, ModelId model);
    /// Rejects NaN/Inf, zero scale and non-unit rotations with an error; the object keeps its old transform.
    Status setTransform(ObjectHandle object, const Transform& transform);
    /// Rejects invalid cameras (validateCamera); the aspect should match the viewport the
    /// view is drawn into. Errors also for an unknown or removed view.
    Status setCamera(const Camera& camera) { return setCamera(kMainView, camera); }
    Status setCamera(ViewId view, const Camera& camera);
    Status setSchedulerParams(const SchedulerParams& params) { return setSchedulerParams(kMainView, params); }
    Status setSchedulerParams(ViewId view, const SchedulerParams& params);
    /// A new view with its own camera and scheduler. Errors: invalid camera or parameters.
    Expected<ViewId> addView(const Camera& camera, const SchedulerParams& params = {});
    /// Removes a view (not the main one); its id stays invalid. Errors: unknown view.
    Status removeView(ViewId view);
    void setQueryParams(const GlQueryParams& params) { backend_->setParams(params); }
    /// Replaces dyncull's renderer for parts (nullptr restores it).
    void setDrawCallback(DrawPartCallback callback) { callback_ = std::move(callback); }
    /// Per-object colour for dyncull's renderer (default: colourForId of the slot).
    void setColour(ObjectHandle object, const glm::vec3& colour);

    /// One frame: relink moved objects, cull, and draw into the bound framebuffer and
    /// viewport (frame_contract.hpp: no clear, the caller's GL state restored; glFinish only
    /// with EngineOptions::finishEachFrame). Does not present.
    /// Errors: the context is not current (WrongContext; nothing done); the GL context was
    /// lost (checked before and after the frame's GL work; from then on every call returns
    /// the same error and does no GL work, see GlContext::checkReset); a GL error raised
    /// during the frame, by dyncull or the draw callback (GlError); the query volume buffers
    /// could not be allocated (the frame was still drawn, its unissued queries counted visible).
    Expected<FrameStats> renderFrame() { return renderView(kMainView); }
    /// The same for another view (errors as above, and BadArgument for an unknown view).
    Expected<FrameStats> renderView(ViewId view);
    /// The main view with another scheduler (its own mode, parameters and visibility
    /// history), so several configurations can be run interleaved over the same frames.
    Expected<FrameStats> renderFrame(QueryScheduler& scheduler);
    /// Draws exactly `parts` (local-BSP nodes: object slot, node), in the given order, with
    /// no culling and no queries, timed like renderFrame (the oracle lower bound of `dyncull
    /// bench`). Every ref must name a live object and a node of its model. Errors: context lost.
    Expected<FrameStats> renderParts(const std::vector<NodeRef>& parts);
    /// The same with each part drawn as index ranges of its model's split mesh (the cluster
    /// oracle of `dyncull bench`): consecutive entries naming one part are its ranges,
    /// ascending, disjoint and inside the part's own range; the part counts once. Drawn in
    /// one multi-draw where the part renderer draws; a game's draw callback gets the whole
    /// part, as in renderFrame.
    Expected<FrameStats> renderPartRanges(std::span<const PartRange> ranges);
    /// The parts the view's last frame drew (renderFrame/renderParts for the main view), in
    /// the order drawn (front to back within each pass); empty after a frame that returned
    /// an error before drawing, and for an unknown view. Valid until the view's next frame.
    std::span<const VisiblePart> visibleParts(ViewId view = kMainView) const;
    /// The objects with a part among visibleParts(view), each once, in the order of their
    /// first part: what a game that draws whole objects draws (conservative modes miss none).
    std::span<const ObjectHandle> visibleObjects(ViewId view = kMainView) const;
    /// True if `object` is among visibleObjects(view); false for a stale handle. O(1).
    bool isVisible(ObjectHandle object, ViewId view = kMainView) const;
    /// Relinks moved objects now (renderFrame does it too; calling twice costs nothing).
    LooseBspFrameStats updateSceneTree();
    /// See EngineOptions::finishEachFrame.
    void setFinishEachFrame(bool finish) { finishEachFrame_ = finish; }
    /// See EngineOptions::submitTriangles; takes effect from the next frame.
    void setSubmitTriangles(std::uint32_t triangles) { submitTriangles_ = triangles; }
    std::uint32_t submitTriangles() const { return submitTriangles_; }
    /// GL errors the caller had left pending when a dyncull call began (taken off the error
    /// flags so they are not reported as dyncull's; see frame_contract.hpp), since creation.
    std::uint64_t callerGlErrors() const { return callerGlErrors_; }

    const SceneObjects& objects() const { return objects_; }
    const LooseBsp& sceneTree() const { return tree_; }
    const LocalBsp& model(ModelId id) const { return objects_.model(id); }
    /// The view's camera (the main view's for an unknown view).
    const Camera& camera(ViewId view = kMainView) const;
    /// dyncull's part renderer; only with EngineOptions::partRenderer.
    Renderer& renderer() {
        assert(renderer_ && "EngineOptions::partRenderer is off");
        return *renderer_;
    }
    bool hasRenderer() const { return renderer_ != nullptr; }
    /// The part renderer's mesh of `model` (its split mesh, uploaded by addModel), or kNoMesh.
    /// meshOf a bounds model added without its box (addBoundsModel's uploadBox false).
    static constexpr MeshId kNoMesh = 0xffffffffu;
    MeshId meshOf(ModelId model) const {
        assert(renderer_ && model < meshOfModel_.size());
        return meshOfModel_[model];
    }
    GlContext& context() { return context_; }
    /// The view's scheduler (the main view's for an unknown view).
    QueryScheduler& scheduler(ViewId view = kMainView);
    GlQueryBackend& queryBackend() { return *backend_; }

    ~Engine();
    Engine(const Engine&) = delete;
    Engine& operator=(const Engine&) = delete;

private:
    Engine(GlContext& context, const EngineOptions& options);
    Expected<ModelId> addModel(LocalBsp bsp, bool upload);
    struct Sink;
    /// What a frame drew, with a per-slot stamp so membership is O(1).
    struct VisibleLists {
        std::vector<VisiblePart> parts;
        std::vector<ObjectHandle> objects;
        std::vector<std::uint32_t> stamp;  // per object slot: `serial` of the last frame that drew it
        std::uint32_t serial = 0;          // frames of this view so far
        void begin(std::uint32_t slots);
    };
    struct View {
        Camera camera;
        std::unique_ptr<QueryScheduler> scheduler;
        VisibleLists visible;
        bool live = true;
    };
    View* findView(ViewId id);
    const View* findView(ViewId id) const;
    /// One frame of `view` with `scheduler`, into the bound framebuffer and viewport.
    Expected<FrameStats> cullAndDraw(View& view, QueryScheduler& scheduler);
    /// The frame around `draw(frameView, sink)`, which returns the frame's stats: checks,
    /// relink, GL state scope, renderer frame, finish and error checks, times. renderParts
    /// and cullAndDraw differ only in `draw`.
    template <class Draw>
    Expected<FrameStats> drawFrame(View& view, const char* what, Draw draw);
    /// Before a call's GL work: the context is current and not lost; the caller's pending
    /// GL errors are set aside (callerGlErrors_).
    Status enterGl(const char* what);
    /// Something draws the parts: the part renderer or a draw callback (BadArgument otherwise).
    Status checkDrawer(const char* what) const;
    /// After it: not lost, and no GL error raised during the call.
    Status leaveGl(const char* what);

    GlContext& context_;
    std::unique_ptr<Renderer> renderer_;
    std::unique_ptr<GlQueryBackend> backend_;
    std::unique_ptr<detail::PartMarks> marks_;  // with the part renderer: tests on the parts' own triangles
    SceneObjects objects_;
    LooseBsp tree_;
    bool treeBuilt_ = false;
    std::vector<View> views_;  // [kMainView] always live
    std::vector<MeshId> meshOfModel_;
    std::vector<glm::vec3> colour_;  // per object slot
    std::vector<std::uint8_t> hasColour_;
    DrawPartCallback callback_;
    bool finishEachFrame_ = false;
    std::uint32_t submitTriangles_ = 0;
    std::uint64_t callerGlErrors_ = 0;
};

}  // namespace dyncull
