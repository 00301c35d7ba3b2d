// The batched raster test: every pending query volume is drawn in one call with colour
// and depth writes off, and each fragment that passes the depth test marks its volume in a
// storage buffer, so one draw and one small readback answer hundreds of volumes exactly
// per pixel. The method of NVIDIA's gl_occlusion_culling sample ("raster" mode; see
// ../shared/notes/batched-occlusion-tests.md); the same volumes, enlargement and depth
// rule as a hardware query (volume_raster.hpp), so both give the same answers.
#include "batched_raster_test.hpp"

#include <algorithm>
#include <cassert>
#include <cstddef>
#include <string>

#include <epoxy/gl.h>
#include <glm/gtc/type_ptr.hpp>

#include "dyncull/engine/gl_context.hpp"
#include "shader_program.hpp"

namespace dyncull::detail {
namespace {

const char* const kVs = R"(#version 450 core
layout(location = 0) in vec3 aPos;
layout(location = 1) in uint aVolume;
uniform mat4 uViewProj;
flat out uint vVolume;
void main() {
    vVolume = aVolume;
    gl_Position = uViewProj * vec4(aPos, 1.0);
}
)";
// Early depth testing: only fragments that pass the depth test run, so a write means a
// visible sample. A plain store, not a count: any sample makes the volume visible.
const char* const kFs = R"(#version 450 core
layout(early_fragment_tests) in;
layout(std430, binding = 0) writeonly buffer Visible { uint visible[]; };
flat in uint vVolume;
void main() { visible[vVolume] = 1u; }
)";
// The error budget's variant: every passing fragment counted. Each pixel of a convex
// volume is covered once by its front faces, so the count is the volume's visible pixels.
const char* const kCountFs = R"(#version 450 core
layout(early_fragment_tests) in;
layout(std430, binding = 0) buffer Samples { uint samples[]; };
flat in uint vVolume;
void main() { atomicAdd(samples[vVolume], 1u); }
)";

}  // namespace

Expected<std::unique_ptr<BatchedRasterTest>> BatchedRasterTest::create(GlContext& context) {
    std::unique_ptr<BatchedRasterTest> t(new BatchedRasterTest(context));
    std::string log;
    t->program_ = buildProgram(kVs, kFs, log);
    if (!t->program_) return Error{"batched raster test shader: " + log};
    t->locViewProj_ = glGetUniformLocation(t->program_, "uViewProj");
    t->countProgram_ = buildProgram(kVs, kCountFs, log);
    if (!t->countProgram_) return Error{"batched raster test's counting shader: " + log};
    t->locCountViewProj_ = glGetUniformLocation(t->countProgram_, "uViewProj");
    glCreateBuffers(1, &t->vbo_);
    glCreateBuffers(1, &t->ibo_);
    glCreateVertexArrays(1, &t->vao_);
    glVertexArrayVertexBuffer(t->vao_, 0, t->vbo_, 0, sizeof(Vertex));
    glVertexArrayElementBuffer(t->vao_, t->ibo_);
    glEnableVertexArrayAttrib(t->vao_, 0);
    glVertexArrayAttribFormat(t->vao_, 0, 3, GL_FLOAT, GL_FALSE, offsetof(Vertex, position));
    glVertexArrayAttribBinding(t->vao_, 0, 0);
    glEnableVertexArrayAttrib(t->vao_, 1);
    glVertexArrayAttribIFormat(t->vao_, 1, 1, GL_UNSIGNED_INT, offsetof(Vertex, volume));
    glVertexArrayAttribBinding(t->vao_, 1, 0);
    return t;
}

BatchedRasterTest::~BatchedRasterTest() {
    if (!context_.isCurrent()) return;  // never delete another context's objects: these die with ours
    for (Batch& b : batches_) glDeleteBuffers(1, &b.buffer);
    glDeleteVertexArrays(1, &vao_);
    glDeleteBuffers(1, &vbo_);
    glDeleteBuffers(1, &ibo_);
    if (program_) glDeleteProgram(program_);
    if (countProgram_) glDeleteProgram(countProgram_);
}

bool BatchedRasterTest::allocate(std::uint32_t buffer, std::size_t bytes, const char* what) {
    glNamedBufferData(buffer, static_cast<GLsizeiptr>(bytes), nullptr, GL_STREAM_DRAW);
    if (Status st = context_.checkAllocation(what, bytes); !st) return false;
    return true;
}

BatchId BatchedRasterTest::draw(std::span<const QueryVolume> volumes, const VolumeView& view,
                                const glm::mat4& viewProjRelative, VolumeTestState& state, bool count) {
    BatchId id;
    if (!free_.empty()) {
        id = free_.back();
        free_.pop_back();
    } else {
        id = static_cast<BatchId>(batches_.size());
        batches_.emplace_back();
        glCreateBuffers(1, &batches_[id].buffer);
    }
    Batch& b = batches_[id];
    b.live = true;
    b.count = static_cast<std::uint32_t>(volumes.size());
    b.counted = count;
    b.visibleUndrawn.assign(volumes.size(), 0);

    // Streams: each volume's points with its index, and its triangles.
    vertices_.clear();
    indices_.clear();
    DrawnVolume drawn;
    for (std::uint32_t i = 0; i < b.count; ++i) {
        if (!prepareVolume(volumes[i], view, drawn)) {
            b.visibleUndrawn[i] = 1;
            continue;
        }
        const auto base = static_cast<std::uint32_t>(vertices_.size());
        for (std::uint32_t k = 0; k < drawn.count; ++k) vertices_.push_back({drawn.points[k], i});
        for (std::uint32_t k = 0; k < drawn.indexCount; ++k) indices_.push_back(base + drawn.indices[k]);
    }

    if (b.capacity < b.count) {
        const std::uint32_t capacity = std::max(b.count, 2 * b.capacity);
        b.capacity = allocate(b.buffer, std::size_t{4} * capacity, "the batched raster test's visibility buffer") ? capacity : 0;
    }
    // Orphaned per draw, so filling them never waits on an earlier batch still rasterising.
    b.drawn = !indices_.empty() && b.capacity >= b.count &&
              allocate(vbo_, vertices_.size() * sizeof(Vertex), "the batched raster test's vertex stream") &&
              allocate(ibo_, indices_.size() * sizeof(std::uint32_t), "the batched raster test's index stream");
    if (!b.drawn) {
        // Nothing to draw (every volume reached the near plane), or no buffer to draw with:
        // then nothing is culled untested.
        std::fill(b.visibleUndrawn.begin(), b.visibleUndrawn.end(), 1);
        return id;
    }
    glNamedBufferSubData(vbo_, 0, static_cast<GLsizeiptr>(vertices_.size() * sizeof(Vertex)), vertices_.data());
    glNamedBufferSubData(ibo_, 0, static_cast<GLsizeiptr>(indices_.size() * sizeof(std::uint32_t)), indices_.data());
    const std::uint32_t zero = 0;
    glClearNamedBufferSubData(b.buffer, GL_R32UI, 0, std::size_t{4} * b.count, GL_RED_INTEGER, GL_UNSIGNED_INT, &zero);

    GLint program = 0, vao = 0, ssbo = 0;
    GLint64 ssboStart = 0, ssboSize = 0;
    glGetIntegerv(GL_CURRENT_PROGRAM, &program);
    glGetIntegerv(GL_VERTEX_ARRAY_BINDING, &vao);
    glGetIntegeri_v(GL_SHADER_STORAGE_BUFFER_BINDING, 0, &ssbo);
    glGetInteger64i_v(GL_SHADER_STORAGE_BUFFER_START, 0, &ssboStart);
    glGetInteger64i_v(GL_SHADER_STORAGE_BUFFER_SIZE, 0, &ssboSize);
    state.enter();
    glUseProgram(count ? countProgram_ : program_);
    glUniformMatrix4fv(count ? locCountViewProj_ : locViewProj_, 1, GL_FALSE, glm::value_ptr(viewProjRelative));
    glBindVertexArray(vao_);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, b.buffer);
    glDrawElements(GL_TRIANGLES, static_cast<GLsizei>(indices_.size()), GL_UNSIGNED_INT, nullptr);
    state.leave();
    if (ssboSize > 0)
        glBindBufferRange(GL_SHADER_STORAGE_BUFFER, 0, static_cast<GLuint>(ssbo), ssboStart, ssboSize);
    else
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, static_cast<GLuint>(ssbo));
    glBindVertexArray(static_cast<GLuint>(vao));
    glUseProgram(static_cast<GLuint>(program));
    return id;
}

void BatchedRasterTest::read(BatchId id, std::span<QueryResult> out, std::span<std::uint32_t> samples) {
    Batch& b = batches_[id];
    assert(b.live && out.size() == b.visibleUndrawn.size() && (samples.empty() || samples.size() == out.size()));
    readback_.assign(b.visibleUndrawn.size(), 0);
    if (b.drawn) {
        // The readback must see the fragments' stores. Issued here, not after the draw:
        // llvmpipe's barrier waits for all drawing, which here, the answer in, is done.
        glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
        glGetNamedBufferSubData(b.buffer, 0, static_cast<GLsizeiptr>(std::size_t{4} * b.count), readback_.data());
    }
    for (std::size_t i = 0; i < out.size(); ++i)
        out[i] = b.visibleUndrawn[i] || readback_[i] ? QueryResult::Visible : QueryResult::Occluded;
    for (std::size_t i = 0; i < samples.size(); ++i)
        samples[i] = b.visibleUndrawn[i] || (!b.counted && readback_[i]) ? kUnknownSamples : readback_[i];
    discard(id);
}

void BatchedRasterTest::discard(BatchId id) {
    assert(batches_[id].live);
    batches_[id].live = false;
    free_.push_back(id);
}

}  // namespace dyncull::detail
