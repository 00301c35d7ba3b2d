// Forward renderer for dyncull scenes: each mesh uploaded once (instances share its
// buffers), drawn per index range with a model matrix, so a local-BSP leaf is one
// glDrawElements on a sub-range with the object's matrix. Simple lighting so shapes
// read clearly in screenshots: Lambert key light + ambient + a view-dependent fill,
// evaluated per vertex by default (Shading).
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include <glm/glm.hpp>

#include "dyncull/engine/gl_context.hpp"
#include "dyncull/engine/image.hpp"
#include "dyncull/objects/camera.hpp"
#include "dyncull/objects/error.hpp"
#include "dyncull/objects/mesh.hpp"
#include "dyncull/objects/surface_orientation.hpp"
#include "dyncull/scheduler/query_backend.hpp"

namespace dyncull {

/// Index of an uploaded mesh in the Renderer (0, 1, 2, ... in upload order).
using MeshId = std::uint32_t;

/// Where the lighting is evaluated. Both give the same terms; per vertex costs a few
/// dozen operations per vertex and leaves the fragment stage a copy, per pixel costs them
/// for every shaded fragment (several per pixel in a dense scene).
enum class Shading : std::uint8_t {
    Vertex,  ///< default
    Pixel,
};

/// Counters of the current (or last) frame; reset by beginFrame.
struct RenderStats {
    std::uint64_t drawCalls = 0;
    std::uint64_t triangles = 0;
};

/// Owns GL buffers/programs; the GlContext it was created with must outlive it and be
/// current whenever a method is called. Destroyed with another context current, it deletes
/// nothing (its objects die with their own context).
class Renderer {
public:
    /// Compiles the shaders. Error only if the driver rejects them.
    static Expected<std::unique_ptr<Renderer>> create(GlContext& context);
    ~Renderer();
    Renderer(const Renderer&) = delete;
    Renderer& operator=(const Renderer&) = delete;

    /// Uploads positions + normals (interleaved) and indices once, to be drawn with back
    /// faces culled or both sides (the mesh's FaceMode, see surface_orientation.hpp: only a
    /// closed, outward surface may be culled without showing holes). Normals are computed
    /// if the mesh has none. The mesh must pass validateMesh (loaders guarantee it) and
    /// have fewer than 2^32 indices. If the driver cannot allocate the buffers
    /// (GL_OUT_OF_MEMORY) returns "out of GPU memory uploading mesh 'name' (N bytes)" and
    /// keeps nothing: buffers made for it are deleted, meshCount() is unchanged.
    Expected<MeshId> upload(const Mesh& mesh, FaceMode faces = FaceMode::TwoSided);
    std::uint32_t indexCount(MeshId id) const { return meshes_[id].indexCount; }
    /// Deletes the mesh's buffers; its id is not reused and must not be drawn again.
    void release(MeshId id);
    std::size_t meshCount() const { return meshes_.size(); }
    /// GPU memory held by mesh buffers, bytes.
    std::size_t uploadedBytes() const { return uploadedBytes_; }

    /// Starts drawing into the framebuffer and viewport the caller has bound, over what they
    /// hold (nothing is cleared; GlContext::clearFramebuffer does that for dyncull's own
    /// frames): depth test with the reversed-Z convention (nearer fragments win with
    /// GL_GREATER; objects/camera.hpp), depth and colour writes on, view/projection from
    /// `camera` (world space; its aspect is used as given: set it to the viewport's).
    /// Changes GL state without restoring it: the Engine calls it inside its state scope.
    void beginFrame(const FrameView& view);
    void beginFrame(const Camera& camera) { beginFrame(FrameView::of(camera, 1, 1)); }
    /// Draws indices [firstIndex, firstIndex + indexCount) of mesh `id` with object-to-world
    /// matrix `model`, in linear-ish RGB `colour` (0..1). Culls back faces if the mesh was
    /// uploaded with FaceMode::CullBack (a mirroring `model` is accounted for).
    /// With a `markSlot`, every fragment that passes the depth test also stores 1 at that
    /// index of the uint storage buffer bound at binding point 1 (detail::kMarksBinding),
    /// which the caller owns, binds and reads (engine/src/part_marks.hpp): whether the
    /// draw showed a sample. With colour and depth writes off the same draw is an exact
    /// occlusion test of the range's own triangles. The image is the same either way.
    void drawRange(MeshId id, std::uint32_t firstIndex, std::uint32_t indexCount, const glm::mat4& model,
                   const glm::vec3& colour, std::uint32_t markSlot = kNoMark);
    /// drawRange of several ranges of mesh `id` at once (one glMultiDrawElements): a part
    /// drawn as its surviving clusters. Counted as one draw call. With `markEachRange`
    /// (needs supportsRangeMarks() and a `markSlot`), range i marks slot markSlot + i, so
    /// each cluster drawn says whether it showed a sample; otherwise the draw marks one slot.
    void drawRanges(MeshId id, std::span<const IndexRange> ranges, const glm::mat4& model, const glm::vec3& colour,
                    std::uint32_t markSlot = kNoMark, bool markEachRange = false);
    /// Whether drawRanges can mark each range (the GL has ARB_shader_draw_parameters, or is 4.6).
    bool supportsRangeMarks() const { return rangeMarks_; }
    /// The exact occlusion test of a range's own triangles: drawRange's fragments (the same
    /// positions, by an invariant expression, and the same face culling), depth-tested
    /// with the current depth function, mark `markSlot` as drawRange's marks do. Only the
    /// fragment's mark is computed: the caller turns colour and depth writes off (else the
    /// test would draw). Not counted in stats().
    void testRange(MeshId id, std::uint32_t firstIndex, std::uint32_t indexCount, const glm::mat4& model,
                   std::uint32_t markSlot);
    void drawMesh(MeshId id, const glm::mat4& model, const glm::vec3& colour) {
        drawRange(id, 0, indexCount(id), model, colour);
    }
    /// Leaves face culling off (as beginFrame set it) and flushes.
    void endFrame();
    /// Blocks until the GPU has finished all submitted work (for honest timings).
    void finish() const;

    /// Reads the context's framebuffer (GlContext::framebuffer, its whole size) as a top-down
    /// RGBA8 image (waits for the GPU). For dyncull's own contexts; leaves the read
    /// framebuffer bound and the pack alignment at 1.
    Image readPixels() const;

    /// Lighting path of the next frames (default Shading::Vertex).
    void setShading(Shading shading) { shading_ = shading; }
    Shading shading() const { return shading_; }
    /// false draws every mesh two-sided whatever its FaceMode (to measure what culling saves).
    void setBackFaceCulling(bool honour) { cullBackFaces_ = honour; }
    /// Whether meshes uploaded with FaceMode::CullBack are drawn with back faces culled.
    bool backFaceCulling() const { return cullBackFaces_; }
    /// true runs only the vertex stage (GL_RASTERIZER_DISCARD from beginFrame to endFrame),
    /// to measure the vertex share of a frame; nothing is drawn. With `vfc` only: occlusion
    /// tests rasterise nothing either, so they would cull everything.
    void setRasteriserDiscard(bool discard) { discard_ = discard; }

    const RenderStats& stats() const { return stats_; }
    const glm::mat4& viewProjection() const { return viewProj_; }
    GlContext& context() { return context_; }

    /// Clear colour (dark grey-blue).
    static constexpr glm::vec3 kClearColour{0.11f, 0.12f, 0.15f};
    /// drawRange without a mark.
    static constexpr std::uint32_t kNoMark = 0xffffffffu;

private:
    explicit Renderer(GlContext& context) : context_(context) {}

    struct GpuMesh {
        std::uint32_t vao = 0, vbo = 0, ibo = 0;
        std::uint32_t indexCount = 0;
        std::size_t bytes = 0;
        bool cullBack = false;
    };
    struct LitProgram {
        std::uint32_t id = 0;
        int viewProj = -1, model = -1, normalMat = -1, colour = -1, viewer = -1, light = -1, markSlot = -1;
    };
    GlContext& context_;
    std::vector<GpuMesh> meshes_;
    std::size_t uploadedBytes_ = 0;
    LitProgram programs_[2][3];  // by Shading, then by detail::MarkKind (plain, per draw, per range; 0 if not built)
    bool rangeMarks_ = false;    // the per-range variants were built
    struct TestProgram {
        std::uint32_t id = 0;
        int viewProj = -1, model = -1, markSlot = -1;
    } testProgram_;
    Shading shading_ = Shading::Vertex;
    bool cullBackFaces_ = true;
    bool discard_ = false;
    bool cullEnabled_ = false, frontCcw_ = true;  // GL culling state as set in this frame (engine/src/face_culling.hpp)
    glm::mat4 viewProj_{1.0f};  // world space (box overlays); parts are drawn camera-relative
    Camera camera_;             // of the current frame, for camera-relative model matrices
    std::vector<int> multiCounts_;            // drawRanges' arguments, reused
    std::vector<const void*> multiOffsets_;
    /// Binds mesh `g`'s program, uniforms, face culling and vertex array for a draw.
    void bindDraw(const GpuMesh& g, const glm::mat4& model, const glm::vec3& colour, std::uint32_t markSlot, bool markEachRange);
    RenderStats stats_;
};

/// A pleasant, well-separated colour for object `id` (stable hash, fixed saturation/value).
glm::vec3 colourForId(std::uint32_t id);

}  // namespace dyncull
