// Storage for the marks of the part renderer's marking shader: which draws, and which parts
// drawn as a test, had a fragment pass the depth test. A batched, exact-per-pixel test on a
// part's own triangles, where the batched raster test (NVIDIA's gl_occlusion_culling
// sample, ../shared/notes/batched-occlusion-tests.md) tests a volume around them.
#include "part_marks.hpp"

#include <algorithm>
#include <cassert>

#include <epoxy/gl.h>

#include "dyncull/engine/gl_context.hpp"
#include "dyncull/engine/renderer.hpp"
#include "shader_program.hpp"

namespace dyncull::detail {

PartMarks::PartMarks(GlContext& context) : context_(context) {
    glCreateBuffers(1, &draws_.name);
    glCreateBuffers(1, &test_.name);
}

PartMarks::~PartMarks() {
    if (!context_.isCurrent()) return;  // never delete another context's objects: these die with ours
    glDeleteBuffers(1, &draws_.name);
    glDeleteBuffers(1, &test_.name);
}

bool PartMarks::reserve(Buffer& b, std::uint32_t count, bool keep) {
    if (count <= b.capacity) return true;
    const std::uint32_t capacity = std::max({count, 2 * b.capacity, 1024u});
    const std::size_t bytes = std::size_t{4} * capacity;
    GLuint grown = 0;
    glCreateBuffers(1, &grown);
    glNamedBufferData(grown, static_cast<GLsizeiptr>(bytes), nullptr, GL_STREAM_READ);
    if (!context_.checkAllocation("the part marks' storage buffer", bytes)) {
        glDeleteBuffers(1, &grown);
        return false;
    }
    const std::uint32_t zero = 0;
    glClearNamedBufferData(grown, GL_R32UI, GL_RED_INTEGER, GL_UNSIGNED_INT, &zero);
    // Copied on the GPU, after the draws that marked the old buffer.
    const std::uint32_t stored = std::min(b.count, b.capacity);
    if (keep && stored > 0) glCopyNamedBufferSubData(b.name, grown, 0, 0, static_cast<GLsizeiptr>(std::size_t{4} * stored));
    glDeleteBuffers(1, &b.name);
    b.name = grown;
    b.capacity = capacity;
    return true;
}

void PartMarks::beginDraws() {
    draws_.count = 0;
    draws_.unmarked.clear();
    if (draws_.capacity > 0) {
        const std::uint32_t zero = 0;
        glClearNamedBufferData(draws_.name, GL_R32UI, GL_RED_INTEGER, GL_UNSIGNED_INT, &zero);
    }
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kMarksBinding, draws_.name);
}

std::uint32_t PartMarks::nextDrawSlots(std::uint32_t count) {
    assert(count > 0);
    const std::uint32_t slot = draws_.count;
    // Each slot is a draw or a drawn cluster, so a frame holds far fewer than 2^32.
    assert(count < Renderer::kNoMark - slot);
    draws_.count += count;
    const bool fits = draws_.count <= draws_.capacity;
    const bool grown = !fits && reserve(draws_, draws_.count, true);
    draws_.unmarked.insert(draws_.unmarked.end(), count, fits || grown ? 0 : 1);
    if (!fits && !grown) return Renderer::kNoMark;
    if (grown) glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kMarksBinding, draws_.name);  // a grown buffer is a new name
    return slot;
}

void PartMarks::skipDrawSlots(std::uint32_t count) {
    assert(count < Renderer::kNoMark - draws_.count);
    draws_.count += count;
    draws_.unmarked.insert(draws_.unmarked.end(), count, 1);
}

void PartMarks::read(Buffer& b, std::span<QueryResult> out) {
    assert(out.size() == b.count);
    const std::uint32_t stored = std::min(b.count, b.capacity);
    readback_.assign(b.count, 0);
    if (stored > 0) {
        // The reads must see the fragments' stores.
        glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
        glGetNamedBufferSubData(b.name, 0, static_cast<GLsizeiptr>(std::size_t{4} * stored), readback_.data());
    }
    for (std::size_t i = 0; i < out.size(); ++i)
        out[i] = readback_[i] || (i < b.unmarked.size() && b.unmarked[i]) ? QueryResult::Visible : QueryResult::Occluded;
}

void PartMarks::readDraws(std::span<QueryResult> out) { read(draws_, out); }

bool PartMarks::beginTest(std::uint32_t count) {
    test_.count = 0;
    test_.unmarked.clear();
    if (!reserve(test_, count, false)) return false;
    const std::uint32_t zero = 0;
    glClearNamedBufferSubData(test_.name, GL_R32UI, 0, std::size_t{4} * count, GL_RED_INTEGER, GL_UNSIGNED_INT, &zero);
    test_.count = count;
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kMarksBinding, test_.name);
    return true;
}

void PartMarks::endTest() { glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kMarksBinding, draws_.name); }

void PartMarks::readTest(std::span<QueryResult> out) { read(test_, out); }

}  // namespace dyncull::detail
