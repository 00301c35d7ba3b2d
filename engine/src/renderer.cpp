// Forward renderer: one VAO/VBO/IBO per mesh, drawn per index range with a model matrix,
// back faces culled for meshes whose surface allows it.
#include "dyncull/engine/renderer.hpp"

#include <cassert>
#include <cmath>
#include <string>

#include <epoxy/gl.h>
#include <glm/gtc/matrix_inverse.hpp>
#include <glm/gtc/type_ptr.hpp>

#include "depth_convention.hpp"
#include "face_culling.hpp"
#include "shader_program.hpp"

namespace dyncull {

Expected<std::unique_ptr<Renderer>> Renderer::create(GlContext& context) {
    std::unique_ptr<Renderer> r(new Renderer(context));
    const char* const sources[2][2] = {{detail::kVertexLitVertexShader, detail::kVertexLitFragmentShader},
                                       {detail::kLitVertexShader, detail::kLitFragmentShader}};
    static_assert(static_cast<int>(Shading::Vertex) == 0 && static_cast<int>(Shading::Pixel) == 1);
    using detail::MarkKind;
    // Marks per range need the draw's range index in the shader (core only from GL 4.6).
    r->rangeMarks_ = epoxy_gl_version() >= 46 || epoxy_has_gl_extension("GL_ARB_shader_draw_parameters");
    for (int i = 0; i < 2; ++i) {
        for (const MarkKind marks : {MarkKind::None, MarkKind::Draw, MarkKind::Range}) {
            if (marks == MarkKind::Range && !r->rangeMarks_) continue;
            std::string log;
            LitProgram& p = r->programs_[i][static_cast<int>(marks)];
            const std::string vertex = detail::litVertexSource(sources[i][0], marks);
            const std::string fragment = detail::litFragmentSource(sources[i][1], marks);
            p.id = detail::buildProgram(vertex.c_str(), fragment.c_str(), log);
            if (!p.id && marks == MarkKind::Range) {  // an extension listed but not compiled: do without
                r->rangeMarks_ = false;
                continue;
            }
            if (!p.id) return Error{"renderer: lit shader rejected by " + context.rendererName() + ": " + log};
            p.viewProj = glGetUniformLocation(p.id, "uViewProj");
            p.model = glGetUniformLocation(p.id, "uModel");
            p.normalMat = glGetUniformLocation(p.id, "uNormalMat");
            p.colour = glGetUniformLocation(p.id, "uColour");
            p.viewer = glGetUniformLocation(p.id, "uViewer");
            p.light = glGetUniformLocation(p.id, "uLightDir");
            p.markSlot = glGetUniformLocation(p.id, "uMarkSlot");  // -1 in the plain variant
        }
    }
    std::string log;
    const std::string testFragment = detail::litFragmentSource(detail::kTriangleTestFragmentShader, detail::MarkKind::Draw);
    TestProgram& t = r->testProgram_;
    t.id = detail::buildProgram(detail::kTriangleTestVertexShader, testFragment.c_str(), log);
    if (!t.id) return Error{"renderer: triangle-test shader rejected by " + context.rendererName() + ": " + log};
    t.viewProj = glGetUniformLocation(t.id, "uViewProj");
    t.model = glGetUniformLocation(t.id, "uModel");
    t.markSlot = glGetUniformLocation(t.id, "uMarkSlot");
    return r;
}

Renderer::~Renderer() {
    if (!context_.isCurrent()) return;  // never delete another context's objects: these die with ours
    for (GpuMesh& m : meshes_) {
        glDeleteVertexArrays(1, &m.vao);
        glDeleteBuffers(1, &m.vbo);
        glDeleteBuffers(1, &m.ibo);
    }
    for (const auto& variants : programs_)
        for (const LitProgram& p : variants)
            if (p.id) glDeleteProgram(p.id);  // 0: a variant not built
    if (testProgram_.id) glDeleteProgram(testProgram_.id);
}

void Renderer::release(MeshId id) {
    assert(id < meshes_.size());
    GpuMesh& m = meshes_[id];
    glDeleteVertexArrays(1, &m.vao);  // 0 names are ignored: releasing twice is harmless
    glDeleteBuffers(1, &m.vbo);
    glDeleteBuffers(1, &m.ibo);
    uploadedBytes_ -= m.bytes;
    m = GpuMesh{};
}

Expected<MeshId> Renderer::upload(const Mesh& mesh, FaceMode faces) {
    assert(validateMesh(mesh).empty());
    Mesh withNormals;
    const Mesh* src = &mesh;
    if (mesh.normals.size() != mesh.positions.size()) {
        withNormals = mesh;
        computeNormals(withNormals);
        src = &withNormals;
    }
    // Interleaved position/normal: one fetch stream per vertex.
    std::vector<glm::vec3> interleaved(src->positions.size() * 2);
    for (std::size_t i = 0; i < src->positions.size(); ++i) {
        interleaved[2 * i] = src->positions[i];
        interleaved[2 * i + 1] = src->normals[i];
    }
    GpuMesh g;
    g.cullBack = faces == FaceMode::CullBack;
    g.indexCount = static_cast<std::uint32_t>(src->indices.size());
    const GLsizeiptr vbytes = static_cast<GLsizeiptr>(interleaved.size() * sizeof(glm::vec3));
    const GLsizeiptr ibytes = static_cast<GLsizeiptr>(src->indices.size() * sizeof(std::uint32_t));
    const std::string what = "uploading mesh " + (mesh.name.empty() ? std::string("(unnamed)") : "'" + mesh.name + "'");
    const std::size_t totalBytes = static_cast<std::size_t>(vbytes + ibytes);
    auto discard = [&g] {  // a failed upload keeps nothing
        glDeleteBuffers(1, &g.vbo);
        glDeleteBuffers(1, &g.ibo);  // 0 (not yet created) is ignored
    };
    glCreateBuffers(1, &g.vbo);
    // Storage must be non-zero sized; an empty mesh still gets valid (1-byte) buffers.
    glNamedBufferStorage(g.vbo, vbytes ? vbytes : 1, vbytes ? interleaved.data() : nullptr, 0);
    if (Status s = context_.checkAllocation(what, totalBytes); !s) {
        discard();
        return s.error();
    }
    glCreateBuffers(1, &g.ibo);
    glNamedBufferStorage(g.ibo, ibytes ? ibytes : 1, ibytes ? src->indices.data() : nullptr, 0);
    if (Status s = context_.checkAllocation(what, totalBytes); !s) {
        discard();
        return s.error();
    }
    glCreateVertexArrays(1, &g.vao);
    glVertexArrayVertexBuffer(g.vao, 0, g.vbo, 0, 2 * sizeof(glm::vec3));
    glVertexArrayElementBuffer(g.vao, g.ibo);
    glEnableVertexArrayAttrib(g.vao, 0);
    glVertexArrayAttribFormat(g.vao, 0, 3, GL_FLOAT, GL_FALSE, 0);
    glVertexArrayAttribBinding(g.vao, 0, 0);
    glEnableVertexArrayAttrib(g.vao, 1);
    glVertexArrayAttribFormat(g.vao, 1, 3, GL_FLOAT, GL_FALSE, sizeof(glm::vec3));
    glVertexArrayAttribBinding(g.vao, 1, 0);
    uploadedBytes_ += totalBytes;
    g.bytes = totalBytes;
    meshes_.push_back(g);
    return static_cast<MeshId>(meshes_.size() - 1);
}

void Renderer::beginFrame(const FrameView& view) {
    const Camera& camera = view.camera;
    stats_ = {};
    // Into the framebuffer and viewport the caller bound, over what it holds (no clear).
    detail::useReversedDepth();
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(detail::kDepthNearer);
    glDepthMask(GL_TRUE);
    glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
    // Back faces are culled per mesh (GpuMesh::cullBack); drawRange switches the state.
    detail::resetFaceCulling(cullEnabled_, frontCcw_);
    if (discard_) glEnable(GL_RASTERIZER_DISCARD);

    viewProj_ = camera.viewProjection();
    // Camera-relative transforms: uViewProj has no translation and uModel carries the
    // object's offset from the eye (computed in double), so the shader's "world" position
    // is relative to the eye and stays precise far from the world origin; the eye is then
    // at the origin for lighting.
    camera_ = camera;
    const glm::mat4 viewProjRel(view.viewProjRelative);
    // Key light over the viewer's left shoulder, so silhouettes and creases get shading.
    const glm::vec3 f = camera.forward();
    glm::vec3 right = glm::cross(f, camera.up);
    right = glm::length(right) > 0.0f ? glm::normalize(right) : glm::vec3(1, 0, 0);
    const glm::vec3 up = glm::cross(right, f);
    const glm::vec3 light = glm::normalize(-f + 0.9f * up - 0.6f * right);

    // Both variants get the frame's uniforms: a frame may mix marked and plain draws.
    // Towards the viewer: from the eye at the origin (camera-relative), or along the view
    // direction for an orthographic camera, whose eye is at infinity.
    const glm::vec4 viewer = camera.orthographic() ? glm::vec4(-camera.forward(), 0.0f) : glm::vec4(0.0f, 0.0f, 0.0f, 1.0f);
    for (const LitProgram& p : programs_[static_cast<int>(shading_)]) {
        if (!p.id) continue;
        glUseProgram(p.id);
        glUniformMatrix4fv(p.viewProj, 1, GL_FALSE, glm::value_ptr(viewProjRel));
        glUniform4fv(p.viewer, 1, glm::value_ptr(viewer));
        glUniform3fv(p.light, 1, glm::value_ptr(light));
    }
    glUseProgram(testProgram_.id);
    glUniformMatrix4fv(testProgram_.viewProj, 1, GL_FALSE, glm::value_ptr(viewProjRel));
}

void Renderer::bindDraw(const GpuMesh& g, const glm::mat4& model, const glm::vec3& colour, std::uint32_t markSlot,
                        bool markEachRange) {
    // Inverse-transpose keeps normals perpendicular under non-uniform scale; done once per
    // draw on the CPU instead of per vertex.
    const glm::mat3 linear(model);
    const glm::mat3 normalMat = glm::inverseTranspose(linear);
    detail::setFaceCulling(cullEnabled_, frontCcw_, g.cullBack && cullBackFaces_, linear);
    const detail::MarkKind marks = markSlot == kNoMark ? detail::MarkKind::None
                                   : markEachRange    ? detail::MarkKind::Range
                                                      : detail::MarkKind::Draw;
    const LitProgram& p = programs_[static_cast<int>(shading_)][static_cast<int>(marks)];
    glUseProgram(p.id);
    if (markSlot != kNoMark) glUniform1ui(p.markSlot, markSlot);
    const glm::mat4 relative = camera_.relativeModel(model);
    glUniformMatrix4fv(p.model, 1, GL_FALSE, glm::value_ptr(relative));
    glUniformMatrix3fv(p.normalMat, 1, GL_FALSE, glm::value_ptr(normalMat));
    // The per-vertex program takes the colour with the display gamma applied (see shaders.cpp).
    const glm::vec3 c = shading_ == Shading::Vertex ? glm::pow(glm::max(colour, glm::vec3(0.0f)), glm::vec3(1.0f / 1.2f)) : colour;
    glUniform3fv(p.colour, 1, glm::value_ptr(c));
    glBindVertexArray(g.vao);
}

void Renderer::drawRange(MeshId id, std::uint32_t firstIndex, std::uint32_t count, const glm::mat4& model,
                         const glm::vec3& colour, std::uint32_t markSlot) {
    assert(id < meshes_.size());
    const GpuMesh& g = meshes_[id];
    assert(firstIndex <= g.indexCount && count <= g.indexCount - firstIndex);
    if (count == 0) return;
    bindDraw(g, model, colour, markSlot, false);
    glDrawElements(GL_TRIANGLES, static_cast<GLsizei>(count), GL_UNSIGNED_INT,
                   reinterpret_cast<const void*>(static_cast<std::uintptr_t>(firstIndex) * sizeof(std::uint32_t)));
    ++stats_.drawCalls;
    stats_.triangles += count / 3;
}

void Renderer::drawRanges(MeshId id, std::span<const IndexRange> ranges, const glm::mat4& model, const glm::vec3& colour,
                          std::uint32_t markSlot, bool markEachRange) {
    assert(!markEachRange || (rangeMarks_ && markSlot != kNoMark));
    assert(id < meshes_.size());
    const GpuMesh& g = meshes_[id];
    if (ranges.empty()) return;
    multiCounts_.clear();
    multiOffsets_.clear();
    for (const IndexRange& r : ranges) {
        assert(r.firstIndex <= g.indexCount && r.indexCount <= g.indexCount - r.firstIndex);
        multiCounts_.push_back(static_cast<GLsizei>(r.indexCount));
        multiOffsets_.push_back(reinterpret_cast<const void*>(static_cast<std::uintptr_t>(r.firstIndex) * sizeof(std::uint32_t)));
        stats_.triangles += r.indexCount / 3;
    }
    bindDraw(g, model, colour, markSlot, markEachRange);
    glMultiDrawElements(GL_TRIANGLES, multiCounts_.data(), GL_UNSIGNED_INT, multiOffsets_.data(),
                        static_cast<GLsizei>(ranges.size()));
    ++stats_.drawCalls;
}

void Renderer::testRange(MeshId id, std::uint32_t firstIndex, std::uint32_t count, const glm::mat4& model,
                         std::uint32_t markSlot) {
    assert(id < meshes_.size() && markSlot != kNoMark);
    const GpuMesh& g = meshes_[id];
    assert(firstIndex <= g.indexCount && count <= g.indexCount - firstIndex);
    if (count == 0) return;
    detail::setFaceCulling(cullEnabled_, frontCcw_, g.cullBack && cullBackFaces_, glm::mat3(model));
    glUseProgram(testProgram_.id);
    glUniform1ui(testProgram_.markSlot, markSlot);
    const glm::mat4 relative = camera_.relativeModel(model);
    glUniformMatrix4fv(testProgram_.model, 1, GL_FALSE, glm::value_ptr(relative));
    glBindVertexArray(g.vao);
    glDrawElements(GL_TRIANGLES, static_cast<GLsizei>(count), GL_UNSIGNED_INT,
                   reinterpret_cast<const void*>(static_cast<std::uintptr_t>(firstIndex) * sizeof(std::uint32_t)));
}

void Renderer::endFrame() {
    detail::resetFaceCulling(cullEnabled_, frontCcw_);  // as beginFrame left it, whatever was drawn last
    if (discard_) glDisable(GL_RASTERIZER_DISCARD);
    glFlush();
}

void Renderer::finish() const { glFinish(); }

Image Renderer::readPixels() const {
    Image img;
    const glm::ivec2 size = context_.size();
    img.width = size.x;
    img.height = size.y;
    const std::size_t rowBytes = static_cast<std::size_t>(size.x) * 4;
    std::vector<std::uint8_t> bottomUp(rowBytes * static_cast<std::size_t>(size.y));
    glBindFramebuffer(GL_READ_FRAMEBUFFER, context_.framebuffer());
    if (context_.framebuffer() == 0) glReadBuffer(GL_BACK);  // window: before the swap
    glPixelStorei(GL_PACK_ALIGNMENT, 1);
    glReadPixels(0, 0, size.x, size.y, GL_RGBA, GL_UNSIGNED_BYTE, bottomUp.data());
    // GL rows start at the bottom; images are top-down.
    img.rgba.resize(bottomUp.size());
    for (int y = 0; y < size.y; ++y)
        std::copy_n(bottomUp.data() + static_cast<std::size_t>(size.y - 1 - y) * rowBytes, rowBytes,
                    img.rgba.data() + static_cast<std::size_t>(y) * rowBytes);
    return img;
}

glm::vec3 colourForId(std::uint32_t id) {
    // Golden-ratio hue steps keep neighbouring ids far apart on the colour wheel; the
    // integer hash decorrelates ids that are multiples of each other.
    std::uint32_t h = id * 0x9E3779B1u;
    h ^= h >> 15;
    h *= 0x85EBCA77u;
    h ^= h >> 13;
    const float hue = std::fmod(static_cast<float>(h & 0xFFFFu) / 65536.0f + 0.61803399f * static_cast<float>(id % 64u), 1.0f);
    const float s = 0.45f, v = 0.9f;
    const float hh = hue * 6.0f;
    const int sector = static_cast<int>(hh) % 6;
    const float fpart = hh - std::floor(hh);
    const float p = v * (1 - s), q = v * (1 - s * fpart), t = v * (1 - s * (1 - fpart));
    switch (sector) {
        case 0: return {v, t, p};
        case 1: return {q, v, p};
        case 2: return {p, v, t};
        case 3: return {p, q, v};
        case 4: return {t, p, v};
        default: return {v, p, q};
    }
}

}  // namespace dyncull
