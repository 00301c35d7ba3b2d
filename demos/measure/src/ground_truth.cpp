// Ground-truth visibility by an ID pass (see ground_truth.hpp), and the bookkeeping that
// compares what a culling mode drew against it.
#include "dyncull/measure/ground_truth.hpp"

#include <algorithm>
#include <cassert>
#include <chrono>

#include <epoxy/gl.h>
#include <glm/gtc/type_ptr.hpp>

#include "dyncull/engine/engine.hpp"
#include "dyncull/engine/gl_context.hpp"
#include "depth_convention.hpp"
#include "face_culling.hpp"
#include "shader_program.hpp"

namespace dyncull {
namespace {

// The vertex stage repeats the lit shader's arithmetic exactly (world = model * p, then
// viewProj * world) so both passes produce bit-identical positions and depths. No
// `invariant` qualifier: the lit shader has none, and it may change how the driver
// compiles the expression (e.g. forbid fused multiply-adds the lit shader gets).
const char* const kIdVertexShader = R"(#version 450 core
layout(location = 0) in vec3 aPosition;
uniform mat4 uViewProj;
uniform mat4 uModel;
void main() {
    vec4 world = uModel * vec4(aPosition, 1.0);
    gl_Position = uViewProj * world;
}
)";

const char* const kIdFragmentShader = R"(#version 450 core
uniform uint uId;
layout(location = 0) out uint outId;
void main() { outId = uId; }
)";

// With cluster ids: the primitive id, counted from the part's first triangle (each part
// is one draw), names the cluster that owns the pixel.
const char* const kIdClusterFragmentShader = R"(#version 450 core
uniform uint uId;
layout(location = 0) out uint outId;
layout(location = 1) out uint outPrimitive;
void main() {
    outId = uId;
    outPrimitive = uint(gl_PrimitiveID);
}
)";

}  // namespace

glm::vec2 GroundTruth::windowDepthRange(const SceneObjects& objects, NodeRef ref, const Camera& camera,
                                        const glm::dmat4& viewProj) {
    const ModelId model = objects.modelOf(ref.object);
    const Aabb local = objects.model(model).nodes[ref.node].box;
    const glm::dmat4 m(objects.matrix(ref.object));
    const glm::dvec3 eye(camera.position);
    const glm::dvec4 distanceRow = camera.distanceRowRelative();
    double lo = 2.0, hi = -1.0;
    for (int c = 0; c < 8; ++c) {
        const glm::dvec3 p((c & 1) ? local.max.x : local.min.x, (c & 2) ? local.max.y : local.min.y,
                           (c & 4) ? local.max.z : local.min.z);
        const glm::dvec4 rel(glm::dvec3(m * glm::dvec4(p, 1.0)) - eye, 1.0);
        const glm::dvec4 clip = viewProj * rel;
        // A corner at or behind the near plane: the clipped part may have any depth.
        if (!(glm::dot(distanceRow, rel) > double(camera.nearPlane))) return {-1.0f, 2.0f};
        const double z = clip.z / clip.w;  // window depth: reversed Z, GL_ZERO_TO_ONE, no remap
        lo = std::min(lo, z);
        hi = std::max(hi, z);
    }
    // Slack far above float rounding of correct fragments (a few ulp of their triangle's
    // largest depth, which is at most hi) and far below the artefacts seen (at about a
    // third of their part's distance, i.e. 3x its depth).
    const double slack = 0x1p-14 * hi;
    return {static_cast<float>(lo - slack), static_cast<float>(hi + slack)};
}

std::uint32_t VisibleSet::pixelsOf(NodeRef key) const {
    const auto it = std::lower_bound(parts.begin(), parts.end(), key);
    if (it == parts.end() || !(*it == key)) return 0;
    return pixels[static_cast<std::size_t>(it - parts.begin())];
}

Expected<std::unique_ptr<GroundTruth>> GroundTruth::create(GlContext& context) {
    std::unique_ptr<GroundTruth> g(new GroundTruth(context));
    std::string log;
    for (int clusters = 0; clusters < 2; ++clusters) {
        IdProgram& p = g->programs_[clusters];
        p.id = detail::buildProgram(kIdVertexShader, clusters ? kIdClusterFragmentShader : kIdFragmentShader, log);
        if (!p.id) return Error{"ground truth: id shader rejected by " + context.rendererName() + ": " + log};
        p.viewProj = glGetUniformLocation(p.id, "uViewProj");
        p.model = glGetUniformLocation(p.id, "uModel");
        p.partId = glGetUniformLocation(p.id, "uId");
    }
    return g;
}

GroundTruth::~GroundTruth() {
    for (std::vector<GpuModel>* list : {&models_, &substitutes_}) {
        for (GpuModel& m : *list) {
            glDeleteVertexArrays(1, &m.vao);
            glDeleteBuffers(1, &m.vbo);
            glDeleteBuffers(1, &m.ibo);
        }
    }
    if (fbo_) glDeleteFramebuffers(1, &fbo_);
    if (colour_) glDeleteTextures(1, &colour_);
    if (primitives_) glDeleteTextures(1, &primitives_);
    if (depth_) glDeleteTextures(1, &depth_);
    for (const IdProgram& p : programs_)
        if (p.id) glDeleteProgram(p.id);
}

void GroundTruth::upload(const Mesh& mesh, GpuModel& g) {
    const auto vbytes = static_cast<GLsizeiptr>(mesh.positions.size() * sizeof(glm::vec3));
    const auto ibytes = static_cast<GLsizeiptr>(mesh.indices.size() * sizeof(std::uint32_t));
    // Storage must be non-zero sized; an empty mesh still gets valid (1-byte) buffers.
    glCreateBuffers(1, &g.vbo);
    glNamedBufferStorage(g.vbo, vbytes ? vbytes : 1, vbytes ? mesh.positions.data() : nullptr, 0);
    glCreateBuffers(1, &g.ibo);
    glNamedBufferStorage(g.ibo, ibytes ? ibytes : 1, ibytes ? mesh.indices.data() : nullptr, 0);
    glCreateVertexArrays(1, &g.vao);
    glVertexArrayVertexBuffer(g.vao, 0, g.vbo, 0, sizeof(glm::vec3));
    glVertexArrayElementBuffer(g.vao, g.ibo);
    glEnableVertexArrayAttrib(g.vao, 0);
    glVertexArrayAttribFormat(g.vao, 0, 3, GL_FLOAT, GL_FALSE, 0);
    glVertexArrayAttribBinding(g.vao, 0, 0);
}

const GroundTruth::GpuModel& GroundTruth::gpuFor(const SceneObjects& objects, std::uint32_t object) {
    if (substitute_) {
        if (substituteTried_.size() <= object) {
            substituteTried_.resize(object + 1, 0);
            substitutes_.resize(object + 1);
        }
        if (!substituteTried_[object]) {
            substituteTried_[object] = 1;
            Mesh mesh;
            if (substitute_(object, mesh)) {
                upload(mesh, substitutes_[object]);
                substitutes_[object].wholeCount = static_cast<std::uint32_t>(mesh.indices.size());
            }
        }
        if (substitutes_[object].vao) return substitutes_[object];
    }
    const ModelId id = objects.modelOf(object);
    if (models_.size() < objects.modelCount()) models_.resize(objects.modelCount());
    GpuModel& g = models_[id];
    if (!g.vao) {
        upload(objects.model(id).mesh, g);
        g.cullBack = objects.model(id).faces == FaceMode::CullBack;
    }
    return g;
}

VisibleSet GroundTruth::compute(const Engine& engine, const Camera& camera) {
    return compute(engine.objects(), camera);
}

VisibleSet GroundTruth::compute(const SceneObjects& objects, const Camera& camera) {
    const auto t0 = std::chrono::steady_clock::now();
    const glm::ivec2 size = context_.size();
    if (size.x != width_ || size.y != height_ || !fbo_) {
        if (fbo_) glDeleteFramebuffers(1, &fbo_);
        if (colour_) glDeleteTextures(1, &colour_);
        if (primitives_) glDeleteTextures(1, &primitives_);
        if (depth_) glDeleteTextures(1, &depth_);
        width_ = size.x;
        height_ = size.y;
        glCreateTextures(GL_TEXTURE_2D, 1, &colour_);
        glTextureStorage2D(colour_, 1, GL_R32UI, width_, height_);
        glCreateTextures(GL_TEXTURE_2D, 1, &primitives_);
        glTextureStorage2D(primitives_, 1, GL_R32UI, width_, height_);
        // Same depth format as the context's FBO, so depth ties resolve identically.
        glCreateTextures(GL_TEXTURE_2D, 1, &depth_);
        glTextureStorage2D(depth_, 1, GL_DEPTH_COMPONENT32F, width_, height_);
        glCreateFramebuffers(1, &fbo_);
        glNamedFramebufferTexture(fbo_, GL_COLOR_ATTACHMENT0, colour_, 0);
        glNamedFramebufferTexture(fbo_, GL_COLOR_ATTACHMENT1, primitives_, 0);
        glNamedFramebufferTexture(fbo_, GL_DEPTH_ATTACHMENT, depth_, 0);
    }

    // Camera-relative, exactly as the renderer: same matrices, so bit-identical depths.
    const glm::mat4 viewProj = camera.viewProjectionRelative();
    candidates_ = frustumLeavesBruteForce(objects, Frustum::fromCamera(camera));

    glBindFramebuffer(GL_FRAMEBUFFER, fbo_);
    const GLenum buffers[2] = {GL_COLOR_ATTACHMENT0, GL_COLOR_ATTACHMENT1};
    glNamedFramebufferDrawBuffers(fbo_, clusterIds_ ? 2 : 1, buffers);
    const IdProgram& program = programs_[clusterIds_ ? 1 : 0];
    glViewport(0, 0, width_, height_);
    glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
    glDepthMask(GL_TRUE);
    glDisable(GL_BLEND);
    // Faces as the renderer draws them: back faces culled per model (LocalBsp::faces).
    bool cullEnabled = false, frontCcw = true;
    detail::resetFaceCulling(cullEnabled, frontCcw);
    detail::useReversedDepth();
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(detail::kDepthNearer);
    const GLuint zero[4] = {0, 0, 0, 0};
    glClearBufferuiv(GL_COLOR, 0, zero);
    if (clusterIds_) glClearBufferuiv(GL_COLOR, 1, zero);
    glClearBufferfv(GL_DEPTH, 0, &detail::kDepthCleared);
    glUseProgram(program.id);
    glUniformMatrix4fv(program.viewProj, 1, GL_FALSE, glm::value_ptr(viewProj));
    for (std::size_t i = 0; i < candidates_.size(); ++i) {
        const NodeRef ref = candidates_[i];
        const ModelId model = objects.modelOf(ref.object);
        const LocalBspNode& n = objects.model(model).nodes[ref.node];
        if (n.indexCount == 0) continue;
        const GpuModel& gm = gpuFor(objects, ref.object);
        static const glm::mat4 identity(1.0f);
        const glm::mat4& toWorld = gm.wholeCount ? identity : objects.matrix(ref.object);
        detail::setFaceCulling(cullEnabled, frontCcw, gm.cullBack, glm::mat3(toWorld));
        glUniform1ui(program.partId, static_cast<GLuint>(i + 1));
        glUniformMatrix4fv(program.model, 1, GL_FALSE, glm::value_ptr(camera.relativeModel(toWorld)));
        glBindVertexArray(gm.vao);
        const std::uint32_t first = gm.wholeCount ? 0 : n.firstIndex, count = gm.wholeCount ? gm.wholeCount : n.indexCount;
        glDrawElements(GL_TRIANGLES, static_cast<GLsizei>(count), GL_UNSIGNED_INT,
                       reinterpret_cast<const void*>(static_cast<std::uintptr_t>(first) * sizeof(std::uint32_t)));
    }
    glBindVertexArray(0);
    detail::resetFaceCulling(cullEnabled, frontCcw);

    const std::size_t rowPixels = static_cast<std::size_t>(width_);
    std::vector<std::uint32_t> bottomUp(rowPixels * static_cast<std::size_t>(height_));
    depths_.resize(bottomUp.size());
    glBindFramebuffer(GL_READ_FRAMEBUFFER, fbo_);
    glReadBuffer(GL_COLOR_ATTACHMENT0);
    glPixelStorei(GL_PACK_ALIGNMENT, 4);
    glReadPixels(0, 0, width_, height_, GL_RED_INTEGER, GL_UNSIGNED_INT, bottomUp.data());
    if (clusterIds_) {
        primitiveIds_.resize(bottomUp.size());
        glReadBuffer(GL_COLOR_ATTACHMENT1);
        glReadPixels(0, 0, width_, height_, GL_RED_INTEGER, GL_UNSIGNED_INT, primitiveIds_.data());
        glReadBuffer(GL_COLOR_ATTACHMENT0);
    }
    glReadPixels(0, 0, width_, height_, GL_DEPTH_COMPONENT, GL_FLOAT, depths_.data());
    glBindFramebuffer(GL_FRAMEBUFFER, context_.framebuffer());
    context_.checkErrors();

    // Rasteriser depth artefacts. A correct fragment of a part lies in the window-depth
    // range of the part's box (the projection of a box in front of the eye is the hull of
    // its projected corners). llvmpipe occasionally writes a fragment of a tiny, nearly
    // edge-on triangle far outside its triangle's depth range (measured under OpenGL's
    // [-1, 1] depth: 0.9881 for a bunny part whose every vertex lies in [0.99611, 0.99639]);
    // such a fragment is not a visible surface point, no query volume can be in front of
    // it, and it is not counted.
    const glm::dmat4 viewProjD = camera.viewProjectionRelativeDouble();
    depthRange_.resize(candidates_.size());
    for (std::size_t i = 0; i < candidates_.size(); ++i)
        depthRange_[i] = windowDepthRange(objects, candidates_[i], camera, viewProjD);
    std::uint32_t artefacts = 0;
    for (std::size_t k = 0; k < bottomUp.size(); ++k) {
        const std::uint32_t id = bottomUp[k];
        if (id == 0 || id > candidates_.size()) continue;
        const glm::vec2 r = depthRange_[id - 1];
        if (depths_[k] < r.x || depths_[k] > r.y) {
            bottomUp[k] = 0;
            ++artefacts;
        }
    }

    ids_.resize(bottomUp.size());
    for (int y = 0; y < height_; ++y)  // GL rows start at the bottom; idImage is top-down
        std::copy_n(bottomUp.data() + static_cast<std::size_t>(height_ - 1 - y) * rowPixels, rowPixels,
                    ids_.data() + static_cast<std::size_t>(y) * rowPixels);

    counts_.assign(candidates_.size() + 1, 0);
    for (std::uint32_t id : ids_)
        if (id <= candidates_.size()) ++counts_[id];  // larger ids cannot occur; ignored defensively
    VisibleSet vs;
    vs.artefactPixels = artefacts;
    vs.candidates = static_cast<std::uint32_t>(candidates_.size());
    for (std::size_t i = 0; i < candidates_.size(); ++i) {
        if (counts_[i + 1] == 0) continue;
        vs.parts.push_back({candidates_[i].object, candidates_[i].node});
        vs.pixels.push_back(counts_[i + 1]);
        vs.coveredPixels += counts_[i + 1];
    }
    // frustumLeavesBruteForce lists slot then node order, so parts are already sorted.
    assert(std::is_sorted(vs.parts.begin(), vs.parts.end()));
    if (clusterIds_) visibleClusters(objects, bottomUp, vs);
    lastMs_ = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    return vs;
}

void GroundTruth::visibleClusters(const SceneObjects& objects, std::span<const std::uint32_t> ids, VisibleSet& vs) {
    // Each pixel's primitive, counted from its part's first index, lies in one cluster of
    // the part (its clusters tile the part's range in index order).
    clusterKeys_.clear();
    for (std::size_t k = 0; k < ids.size(); ++k) {
        const std::uint32_t id = ids[k];
        if (id == 0 || id > candidates_.size()) continue;
        const NodeRef ref = candidates_[id - 1];
        if (ref.object < substitutes_.size() && substitutes_[ref.object].vao) continue;  // not the model's triangles
        const LocalBsp& model = objects.model(objects.modelOf(ref.object));
        if (!model.clusters.builtFor(model.nodes.size())) continue;
        const LocalBspNode& n = model.nodes[ref.node];
        const std::span<const LeafCluster> clusters = model.clusters.ofSubtree(ref.node, n.subtreeSize);
        if (clusters.empty()) continue;
        const std::uint64_t index = std::uint64_t{n.firstIndex} + 3 * std::uint64_t{primitiveIds_[k]};
        auto after = std::upper_bound(clusters.begin(), clusters.end(), index,
                                      [](std::uint64_t i, const LeafCluster& c) { return i < c.firstIndex; });
        if (after == clusters.begin()) continue;  // cannot happen: the first cluster starts at the part's first index
        const auto c = static_cast<std::uint32_t>(model.clusters.nodeFirst[ref.node] + (after - 1 - clusters.begin()));
        clusterKeys_.push_back(std::uint64_t{id - 1} << 32 | c);
    }
    std::sort(clusterKeys_.begin(), clusterKeys_.end());  // one key per pixel: a run of equal keys is a cluster's pixels
    // Visible parts are the candidates with pixels, in candidate order, as are the keys.
    vs.clusterFirst.assign(1, 0);
    vs.clusters.clear();
    vs.clusterPixels.clear();
    vs.visibleClusterTriangles = 0;
    std::size_t key = 0;
    for (std::size_t p = 0; p < vs.parts.size(); ++p) {
        const NodeRef ref = vs.parts[p];
        while (key < clusterKeys_.size() && candidates_[clusterKeys_[key] >> 32] < ref) ++key;
        const LocalBsp& model = objects.model(objects.modelOf(ref.object));
        const std::size_t before = vs.clusters.size();
        while (key < clusterKeys_.size() && candidates_[clusterKeys_[key] >> 32] == ref) {
            const std::uint64_t k = clusterKeys_[key];
            const std::size_t end = static_cast<std::size_t>(
                std::upper_bound(clusterKeys_.begin() + static_cast<std::ptrdiff_t>(key), clusterKeys_.end(), k) - clusterKeys_.begin());
            const auto c = static_cast<std::uint32_t>(k & 0xffffffffu);
            vs.clusters.push_back(c);
            vs.clusterPixels.push_back(static_cast<std::uint32_t>(end - key));
            vs.visibleClusterTriangles += model.clusters.clusters[c].indexCount / 3;
            key = end;
        }
        if (vs.clusters.size() == before) vs.visibleClusterTriangles += model.nodes[ref.node].indexCount / 3;  // no clusters: the whole part
        vs.clusterFirst.push_back(static_cast<std::uint32_t>(vs.clusters.size()));
    }
}

std::vector<NodeRef> drawnLeaves(const SceneObjects& objects, std::span<const VisiblePart> parts) {
    std::vector<NodeRef> leaves;
    for (const VisiblePart& p : parts) {
        const LocalBsp& bsp = objects.model(objects.modelOf(p.part.object));
        // Depth-first storage: the subtree of node n is nodes [n, n + subtreeSize).
        const std::uint32_t first = p.part.node, end = first + bsp.nodes[first].subtreeSize;
        for (std::uint32_t n = first; n < end; ++n)
            if (bsp.nodes[n].isLeaf() && (bsp.nodes[n].indexCount > 0 || bsp.nodes.size() == 1))
                leaves.push_back({p.part.object, n});  // empty leaves own no pixels
    }
    std::sort(leaves.begin(), leaves.end());
    leaves.erase(std::unique(leaves.begin(), leaves.end()), leaves.end());
    return leaves;
}

PartErrors compareParts(const VisibleSet& truth, const std::vector<NodeRef>& drawn) {
    PartErrors e;
    e.drawn = static_cast<std::uint32_t>(drawn.size());
    std::size_t i = 0, j = 0;  // merge of two sorted lists
    while (i < truth.parts.size() || j < drawn.size()) {
        if (j == drawn.size() || (i < truth.parts.size() && truth.parts[i] < drawn[j])) {
            ++e.falseNegatives;
            e.falseNegativePixels += truth.pixels[i];
            ++i;
        } else if (i == truth.parts.size() || drawn[j] < truth.parts[i]) {
            ++e.falsePositives;
            ++j;
        } else {
            ++i;
            ++j;
        }
    }
    return e;
}

}  // namespace dyncull
