// GL occlusion-query backend. Paper: Two-level BSP for dynamic occlusion culling,
// section 3.4 (queries on node boxes, several in flight at once); k-DOP query meshes per
// kdop-bounding-volumes-for-occlusion.txt, section 4 (bounding volume drawn with depth
// and colour writes off).
#include "dyncull/engine/gl_query_backend.hpp"

#include <algorithm>
#include <array>
#include <cassert>
#include <cmath>
#include <chrono>
#include <cstdint>
#include <cstring>
#include <limits>
#include <span>
#include <string>
#include <thread>

#include <epoxy/gl.h>
#include <glm/gtc/type_ptr.hpp>

#include "dyncull/engine/gl_context.hpp"
#include "batched_raster_test.hpp"
#include "shader_program.hpp"
#include "volume_raster.hpp"

namespace dyncull {
namespace {

const char* const kVolumeVs = R"(#version 450 core
layout(location = 0) in vec3 aPos;
uniform mat4 uViewProj;
void main() { gl_Position = uViewProj * vec4(aPos, 1.0); }
)";
const char* const kVolumeFs = R"(#version 450 core
void main() {}
)";

// Streaming capacity at start (grows by doubling): 4096 boxes with their snapping rings
// (8 + 4 x 6 points, 3 x (12 + 2 x 6) indices).
constexpr std::uint32_t kInitialVertices = 4096 * 32;
constexpr std::uint32_t kInitialIndices = 4096 * 72;

}  // namespace

GlQueryBackend::GlQueryBackend(GlContext& context, GlQueryParams params) : context_(context), params_(params) {}

Expected<std::unique_ptr<GlQueryBackend>> GlQueryBackend::create(GlContext& context, GlQueryParams params) {
    std::unique_ptr<GlQueryBackend> b(new GlQueryBackend(context, params));
    std::string log;
    b->program_ = detail::buildProgram(kVolumeVs, kVolumeFs, log);
    if (!b->program_) return Error{"query volume shader: " + log};
    b->locViewProj_ = glGetUniformLocation(b->program_, "uViewProj");
    b->rasterState_ = std::make_unique<detail::VolumeTestState>();
    auto batches = detail::BatchedRasterTest::create(context);
    if (!batches) return Error{"query backend: " + batches.error().message};
    b->batches_ = batches.take();
    b->view_ = std::make_unique<detail::VolumeView>();
    glGetIntegerv(GL_SUBPIXEL_BITS, &b->subpixelBits_);
    // Every volume streams its points and 8-bit indices (its triangles and its snapping ring).
    glCreateBuffers(1, &b->ibo_);
    glCreateBuffers(1, &b->vbo_);
    b->iboCapacity_ = kInitialIndices;
    b->vboCapacity_ = kInitialVertices;
    // On failure the destructor deletes what was created.
    glNamedBufferData(b->ibo_, b->iboCapacity_, nullptr, GL_STREAM_DRAW);
    if (Status st = context.checkAllocation("creating the query volume index buffer", b->iboCapacity_); !st)
        return Error{"query backend: " + st.message()};
    glNamedBufferData(b->vbo_, b->vboCapacity_ * sizeof(glm::vec3), nullptr, GL_STREAM_DRAW);
    if (Status st = context.checkAllocation("creating the query volume vertex buffer", b->vboCapacity_ * sizeof(glm::vec3)); !st)
        return Error{"query backend: " + st.message()};
    glCreateVertexArrays(1, &b->vao_);
    glVertexArrayVertexBuffer(b->vao_, 0, b->vbo_, 0, sizeof(glm::vec3));
    glVertexArrayElementBuffer(b->vao_, b->ibo_);
    glEnableVertexArrayAttrib(b->vao_, 0);
    glVertexArrayAttribFormat(b->vao_, 0, 3, GL_FLOAT, GL_FALSE, 0);
    glVertexArrayAttribBinding(b->vao_, 0, 0);
    return b;
}

GlQueryBackend::~GlQueryBackend() {
    if (!context_.isCurrent()) {
        batches_.reset();  // its buffers, like ours, die with their own context
        return;
    }
    // Deleting a query drops its fence reference: first let every fence finish signalling
    // (see free_ in the header).
    glFinish();
    for (Slot& s : queries_) glDeleteQueries(1, &s.name);
    glDeleteVertexArrays(1, &vao_);
    glDeleteBuffers(1, &vbo_);
    glDeleteBuffers(1, &ibo_);
    if (program_) glDeleteProgram(program_);
}

void GlQueryBackend::beginFrame(const FrameView& frame) {
    // Camera-relative like the renderer: volumes are uploaded relative to the eye.
    viewProj_ = glm::mat4(frame.viewProjRelative);
    *view_ = detail::VolumeView::of(frame, params_.snapping, subpixelBits_);
    // Orphan last frame's volumes so writing this frame's never waits on the rasteriser;
    // a buffer last frame did not write is left alone (a software GL fills new storage,
    // 1.5 MB for the vertices: 0.15 ms a frame in two-phase, which issues no query).
    // After a failed allocation both buffers are allocated again (either may have no storage).
    const bool retry = degraded_;
    degraded_ = false;
    frameStatus_ = {};
    const bool usedVbo = vboUsed_ > 0 || retry, usedIbo = iboUsed_ > 0 || retry;
    vboUsed_ = 0;
    iboUsed_ = 0;
    if (usedVbo && !allocate(vbo_, vboCapacity_ * sizeof(glm::vec3), "orphaning the query volume vertex buffer")) return;
    if (usedIbo) allocate(ibo_, iboCapacity_, "orphaning the query volume index buffer");
}

bool GlQueryBackend::allocate(std::uint32_t buffer, std::size_t bytes, const char* what) {
    glNamedBufferData(buffer, static_cast<GLsizeiptr>(bytes), nullptr, GL_STREAM_DRAW);
    if (Status st = context_.checkAllocation(what, bytes); !st) {
        degraded_ = true;
        frameStatus_ = Error{"query backend: " + st.message() + "; queries counted visible until it succeeds"};
        return false;
    }
    return true;
}

QueryId GlQueryBackend::acquireSlot() {
    if (!free_.empty() && queries_[free_.front()].releaseMark < answeredSerial_) {
        const QueryId id = free_.front();
        free_.pop_front();
        return id;
    }
    const QueryId id = static_cast<QueryId>(queries_.size());
    queries_.emplace_back();
    glCreateQueries(GL_ANY_SAMPLES_PASSED_CONSERVATIVE, 1, &queries_[id].name);
    queries_[id].target = GL_ANY_SAMPLES_PASSED_CONSERVATIVE;
    return id;
}

QueryId GlQueryBackend::answeredVisible() {
    // Never begun in GL, so any released slot will do (its query object stays untouched).
    QueryId id;
    if (!free_.empty()) {
        id = free_.back();
        free_.pop_back();
    } else {
        id = acquireSlot();
    }
    Slot& s = queries_[id];
    s.live = true;
    s.result = QueryResult::Visible;
    s.samples = 0;
    return id;
}

QueryId GlQueryBackend::startQuery() {
    const QueryId id = acquireSlot();
    Slot& s = queries_[id];
    const std::uint32_t target = params_.visiblePixelThreshold > 0 ? GL_SAMPLES_PASSED : GL_ANY_SAMPLES_PASSED_CONSERVATIVE;
    if (s.target != target) {
        // A query object is bound to the target it was created for.
        glDeleteQueries(1, &s.name);
        glCreateQueries(target, 1, &s.name);
        s.target = target;
    }
    s.live = true;
    s.result = QueryResult::NotReady;
    s.samples = 0;
    s.begun = ++beginSerial_;  // every caller begins it in GL next
    return id;
}

QueryId GlQueryBackend::beginDrawQuery() {
    assert(!inBatch_ && !inDrawQuery_);
    inDrawQuery_ = true;
    const QueryId id = startQuery();
    glBeginQuery(queries_[id].target, queries_[id].name);
    return id;
}

void GlQueryBackend::endDrawQuery(QueryId id) {
    assert(inDrawQuery_ && queries_[id].live);
    inDrawQuery_ = false;
    glEndQuery(queries_[id].target);
}

bool GlQueryBackend::readDepth(std::vector<float>& depth, int& width, int& height) {
    if (!hasTarget_ || !target_.depthReadable) return false;
    width = target_.width();
    height = target_.height();
    depth.resize(static_cast<std::size_t>(width) * static_cast<std::size_t>(height));
    // Into client memory, tightly packed, whatever pack state the caller left.
    GLint readFbo = 0, packBuffer = 0, alignment = 4, rowLength = 0, skipRows = 0, skipPixels = 0;
    glGetIntegerv(GL_READ_FRAMEBUFFER_BINDING, &readFbo);
    glGetIntegerv(GL_PIXEL_PACK_BUFFER_BINDING, &packBuffer);
    glGetIntegerv(GL_PACK_ALIGNMENT, &alignment);
    glGetIntegerv(GL_PACK_ROW_LENGTH, &rowLength);
    glGetIntegerv(GL_PACK_SKIP_ROWS, &skipRows);
    glGetIntegerv(GL_PACK_SKIP_PIXELS, &skipPixels);
    glBindFramebuffer(GL_READ_FRAMEBUFFER, target_.framebuffer);
    glBindBuffer(GL_PIXEL_PACK_BUFFER, 0);
    glPixelStorei(GL_PACK_ALIGNMENT, 4);
    glPixelStorei(GL_PACK_ROW_LENGTH, 0);
    glPixelStorei(GL_PACK_SKIP_ROWS, 0);
    glPixelStorei(GL_PACK_SKIP_PIXELS, 0);
    glReadPixels(target_.viewport.x, target_.viewport.y, width, height, GL_DEPTH_COMPONENT, GL_FLOAT, depth.data());
    glPixelStorei(GL_PACK_ALIGNMENT, alignment);
    glPixelStorei(GL_PACK_ROW_LENGTH, rowLength);
    glPixelStorei(GL_PACK_SKIP_ROWS, skipRows);
    glPixelStorei(GL_PACK_SKIP_PIXELS, skipPixels);
    glBindBuffer(GL_PIXEL_PACK_BUFFER, static_cast<GLuint>(packBuffer));
    glBindFramebuffer(GL_READ_FRAMEBUFFER, static_cast<GLuint>(readFbo));
    return true;
}

void GlQueryBackend::finishDrawing() { glFinish(); }

void GlQueryBackend::beginBatch() {
    assert(!inBatch_ && !inDrawQuery_);
    inBatch_ = true;
    rasterState_->enter();
    glUseProgram(program_);
    glUniformMatrix4fv(locViewProj_, 1, GL_FALSE, glm::value_ptr(viewProj_));
    glBindVertexArray(vao_);
}

QueryId GlQueryBackend::issue(const QueryVolume& volume) {
    assert(inBatch_);
    assert(volume.vertexCount <= QueryVolume::kMaxVertices && volume.triangleCount <= QueryVolume::kMaxTriangles);
    assert(!volume.isBox() || volume.vertexCount == 8);
    // Vertices relative to the eye, the volume enlarged to cover the float rounding its
    // world coordinates may carry, so a volume 1e7 units from the origin is never smaller
    // than the geometry it bounds and the query stays conservative.
    detail::DrawnVolume drawn;
    if (!detail::prepareVolume(volume, *view_, drawn)) return answeredVisible();
    const std::uint32_t nv = drawn.count, ni = drawn.indexCount;
    // Grow by doubling: earlier draws of this frame keep the orphaned storage they
    // referenced. On failure the capacity stays at the last size that worked.
    if (!degraded_ && vboUsed_ + nv > vboCapacity_ &&
        allocate(vbo_, std::size_t{2} * vboCapacity_ * sizeof(glm::vec3), "growing the query volume vertex buffer")) {
        vboCapacity_ *= 2;
        vboUsed_ = 0;
    }
    if (!degraded_ && iboUsed_ + ni > iboCapacity_ &&
        allocate(ibo_, std::size_t{2} * iboCapacity_, "growing the query volume index buffer")) {
        iboCapacity_ *= 2;
        iboUsed_ = 0;
    }
    if (degraded_) return answeredVisible();  // no buffer to draw the volume from: never culls, never waits
    glNamedBufferSubData(vbo_, vboUsed_ * sizeof(glm::vec3), nv * sizeof(glm::vec3), drawn.points.data());
    glNamedBufferSubData(ibo_, iboUsed_, ni, drawn.indices.data());

    const QueryId id = startQuery();
    const std::uint32_t target = queries_[id].target;
    glBeginQuery(target, queries_[id].name);
    glDrawElementsBaseVertex(GL_TRIANGLES, static_cast<GLsizei>(ni), GL_UNSIGNED_BYTE,
                             reinterpret_cast<const void*>(static_cast<std::uintptr_t>(iboUsed_)), static_cast<GLint>(vboUsed_));
    glEndQuery(target);
    iboUsed_ += ni;
    vboUsed_ += nv;
    return id;
}

void GlQueryBackend::endBatch() {
    assert(inBatch_);
    inBatch_ = false;
    rasterState_->leave();
    // Submit now so the rasteriser works on the queries while the CPU traverses on.
    if (params_.flushAfterBatch) glFlush();
}

QueryResult GlQueryBackend::fetch(QueryId id) {
    Slot& s = queries_[id];
    assert(s.live);
    if (s.result != QueryResult::NotReady) return s.result;
    GLuint available = 0;
    glGetQueryObjectuiv(s.name, GL_QUERY_RESULT_AVAILABLE, &available);
    if (!available) return QueryResult::NotReady;
    answeredSerial_ = std::max(answeredSerial_, s.begun);
    GLuint64 value = 0;
    glGetQueryObjectui64v(s.name, GL_QUERY_RESULT, &value);
    s.samples = value;
    const bool visible = s.target == GL_SAMPLES_PASSED ? value > params_.visiblePixelThreshold : value != 0;
    s.result = visible ? QueryResult::Visible : QueryResult::Occluded;
    return s.result;
}

QueryResult GlQueryBackend::poll(QueryId id) { return fetch(id); }

QueryResult GlQueryBackend::wait(QueryId id, double timeoutMs) {
    const auto t0 = std::chrono::steady_clock::now();
    glFlush();
    for (;;) {
        const QueryResult r = fetch(id);
        if (r != QueryResult::NotReady) return r;
        const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
        if (ms > timeoutMs) return QueryResult::NotReady;  // caller counts it visible
        std::this_thread::yield();
    }
}

void GlQueryBackend::release(QueryId id) {
    assert(queries_[id].live);
    queries_[id].live = false;
    queries_[id].releaseMark = beginSerial_;
    free_.push_back(id);
}

std::uint64_t GlQueryBackend::samples(QueryId id) const { return queries_[id].samples; }

BatchId GlQueryBackend::testVolumes(std::span<const QueryVolume> volumes, bool countSamples) {
    assert(!inBatch_ && !inDrawQuery_);
    // A query around the draw tells without blocking when the batch has been rasterised;
    // its slot goes through the same safe-reuse queue as any query (see free_).
    const QueryId q = startQuery();
    glBeginQuery(queries_[q].target, queries_[q].name);
    const BatchId id = batches_->draw(volumes, *view_, viewProj_, *rasterState_, countSamples);
    glEndQuery(queries_[q].target);
    if (params_.flushAfterBatch) glFlush();
    if (batchQuery_.size() <= id) batchQuery_.resize(id + 1, kNoQuery);
    batchQuery_[id] = q;
    return id;
}

bool GlQueryBackend::collectVolumes(BatchId id, std::span<QueryResult> out, double waitMs,
                                    std::span<std::uint32_t> samples) {
    assert(samples.empty() || samples.size() == out.size());
    assert(id < batchQuery_.size() && batchQuery_[id] != kNoQuery);
    const QueryId q = batchQuery_[id];
    const QueryResult done = waitMs > 0 ? wait(q, waitMs) : poll(q);
    if (done == QueryResult::NotReady && waitMs <= 0) return false;
    if (done == QueryResult::NotReady) {
        batches_->discard(id);  // timed out: never cull, never stall forever
        std::fill(out.begin(), out.end(), QueryResult::Visible);
        std::fill(samples.begin(), samples.end(), kUnknownSamples);
    } else {
        batches_->read(id, out, samples);
    }
    release(q);
    batchQuery_[id] = kNoQuery;
    return true;
}

}  // namespace dyncull
