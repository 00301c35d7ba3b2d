// Exact visibility of object parts for measuring culling modes: an ID pass draws every
// local-BSP leaf of every live object that is not outside the frustum (no occlusion
// culling) with its part id into an integer target, depth-tested exactly like the
// renderer (same positions, matrices, reversed Z with GL_GREATER, 32-bit float depth),
// and reads it back.
// A part is visible iff it owns at least one pixel; its pixel count comes with it.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <span>
#include <vector>

#include "dyncull/bsp/scene_objects.hpp"
#include "dyncull/bsp/traversal.hpp"
#include "dyncull/engine/engine.hpp"
#include "dyncull/objects/camera.hpp"
#include "dyncull/objects/error.hpp"

namespace dyncull {

class Engine;
class GlContext;

/// The parts visible in one frame, sorted by key, with the pixels each covers.
struct VisibleSet {
    std::vector<NodeRef> parts;          ///< sorted ascending, unique
    std::vector<std::uint32_t> pixels;   ///< pixels[i]: pixels part i owns (> 0)
    std::uint64_t coveredPixels = 0;     ///< sum of pixels (pixels showing any part)
    std::uint32_t candidates = 0;        ///< parts drawn by the ID pass (not outside the frustum)
    /// ID-pass pixels dropped as rasteriser depth artefacts: the fragment's depth lies
    /// outside the window-depth range of its own part's box, so it is no surface point
    /// (see GroundTruth::compute). Not in `pixels` nor `coveredPixels`.
    std::uint32_t artefactPixels = 0;
    /// Per visible part i, the clusters owning at least one of its pixels:
    /// clusters[clusterFirst[i] .. clusterFirst[i + 1]), ascending indices into its model's
    /// LocalBsp::clusters. None for a part without clusters or drawn from a substitute mesh
    /// (its pixels are the part's alone). clusterFirst has parts.size() + 1 entries.
    std::vector<std::uint32_t> clusterFirst;  ///< empty unless GroundTruth::setClusterIds
    std::vector<std::uint32_t> clusters;
    std::vector<std::uint32_t> clusterPixels;  ///< clusterPixels[k]: pixels clusters[k] owns (> 0)
    /// Triangles of those clusters, plus the whole triangles of visible parts without
    /// clusters: what a culler at cluster granularity must draw at least.
    std::uint64_t visibleClusterTriangles = 0;

    /// Pixels of `key`, 0 if not visible. O(log n).
    std::uint32_t pixelsOf(NodeRef key) const;
    bool contains(NodeRef key) const { return pixelsOf(key) > 0; }
};

/// Owns an FBO (R32UI ids, R32UI primitive ids within each part's draw, DEPTH32F) the size of the context and its own copy of every
/// model's positions and indices (uploaded on first use; models are never removed). The
/// GlContext must outlive it and be current on every call. Leaves the context's
/// framebuffer bound afterwards; other GL state the renderer sets per frame anyway.
class GroundTruth {
public:
    static Expected<std::unique_ptr<GroundTruth>> create(GlContext& context);
    ~GroundTruth();
    GroundTruth(const GroundTruth&) = delete;
    GroundTruth& operator=(const GroundTruth&) = delete;

    /// The exact visible set of the engine's scene from `camera` (world space; the aspect
    /// should match the context). Uses the objects' current matrices.
    VisibleSet compute(const Engine& engine, const Camera& camera);
    VisibleSet compute(const SceneObjects& objects, const Camera& camera);

    /// Geometry drawn for an object (by slot) instead of its model's mesh: world space,
    /// drawn whole and two-sided with no object transform. For streamed leaves, whose
    /// models are boxes standing for them (StreamedObjects). Called once per object, when
    /// it is first in the frustum; false keeps the model's mesh.
    using MeshSubstitute = std::function<bool(std::uint32_t objectSlot, Mesh&)>;
    void setMeshSubstitute(MeshSubstitute substitute) { substitute_ = std::move(substitute); }

    /// Whether compute also finds each visible part's visible clusters (VisibleSet::clusters,
    /// visibleClusterTriangles; else those stay empty and 0). Off by default: the ID pass
    /// then writes each fragment's primitive id too, which took it twice as long on llvmpipe.
    void setClusterIds(bool on) { clusterIds_ = on; }
    /// Ids of the last compute, top-down rows, width x height: 0 = background, else
    /// 1 + index into lastParts().
    const std::vector<std::uint32_t>& idImage() const { return ids_; }
    /// The per-frame part list the ids index (frustum-culled leaves, slot then node order).
    const std::vector<NodeRef>& lastParts() const { return candidates_; }
    /// Milliseconds of the last compute (draw + readback + counting).
    double lastMs() const { return lastMs_; }

private:
    explicit GroundTruth(GlContext& context) : context_(context) {}
    /// Window-depth interval (reversed Z; with rounding slack) that every correct fragment
    /// of leaf `ref` lies in; [-1, 2] (no constraint) if its box reaches the near plane.
    /// `viewProj`: camera.viewProjectionRelativeDouble().
    /// Fills vs.clusterFirst, clusters and visibleClusterTriangles from the last ID pass
    /// (`ids`: its part ids after artefact removal, GL rows).
    void visibleClusters(const SceneObjects& objects, std::span<const std::uint32_t> ids, VisibleSet& vs);
    static glm::vec2 windowDepthRange(const SceneObjects& objects, NodeRef ref, const Camera& camera,
                                      const glm::dmat4& viewProj);

    struct GpuModel {
        std::uint32_t vao = 0, vbo = 0, ibo = 0;
        bool cullBack = false;  // the model's FaceMode, as the renderer draws it
        std::uint32_t wholeCount = 0;  // > 0: a substitute mesh, drawn whole and untransformed
    };
    std::vector<GpuModel> substitutes_;            // by object slot
    std::vector<std::uint8_t> substituteTried_;    // by object slot
    /// Uploads `mesh` into `g` (positions and indices).
    static void upload(const Mesh& mesh, GpuModel& g);
    /// The GPU copy to draw for `object`: its substitute, else its model's (uploaded on first use).
    const GpuModel& gpuFor(const SceneObjects& objects, std::uint32_t object);

    GlContext& context_;
    MeshSubstitute substitute_;
    std::uint32_t fbo_ = 0, colour_ = 0, primitives_ = 0, depth_ = 0;
    struct IdProgram {
        std::uint32_t id = 0;
        int viewProj = -1, model = -1, partId = -1;
    };
    IdProgram programs_[2];  // [with cluster ids]
    bool clusterIds_ = false;
    int width_ = 0, height_ = 0;
    std::vector<GpuModel> models_;
    std::vector<NodeRef> candidates_;
    std::vector<std::uint32_t> ids_;
    std::vector<std::uint32_t> counts_;
    std::vector<std::uint32_t> primitiveIds_;    // last ID pass, GL rows (bottom-up)
    std::vector<std::uint64_t> clusterKeys_;     // (candidate << 32 | cluster) of each pixel
    std::vector<float> depths_;        // last ID pass depth, GL rows (bottom-up)
    std::vector<glm::vec2> depthRange_;  // per candidate: windowDepthRange
    double lastMs_ = 0.0;
};

/// The non-empty leaves covered by the parts a frame drew (Engine::visibleParts), sorted
/// and unique: a drawn part is a leaf, or an inner node whose whole subtree was drawn in one
/// call (a single-node model's root counts even when empty).
std::vector<NodeRef> drawnLeaves(const SceneObjects& objects, std::span<const VisiblePart> parts);

/// How a drawn set differs from the visible set.
struct PartErrors {
    std::uint32_t falseNegatives = 0;        ///< visible parts not drawn
    std::uint64_t falseNegativePixels = 0;   ///< pixels those parts own in the ground truth
    std::uint32_t falsePositives = 0;        ///< drawn parts with no visible pixel
    std::uint32_t drawn = 0;
};
/// `drawn` sorted and unique (drawnLeaves).
PartErrors compareParts(const VisibleSet& truth, const std::vector<NodeRef>& drawn);

}  // namespace dyncull
