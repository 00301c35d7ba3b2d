// A headless game that embeds dyncull only to decide what to draw.
//
// The game owns everything a game owns: its EGL context and framebuffer, its meshes with
// its own vertex attributes (a colour per vertex), its shader and its motion. dyncull
// borrows the context, and each frame calls back with the visible parts, which the game
// draws from its own buffers.
//
//   headless_game [--frames N] [--screenshot FILE.png] [--cull none|vfc|full|queries] [--check]
//
// --cull none draws every object without asking dyncull. --check draws the last frame
// that way too and compares: a conservative mode must give the same picture (the program
// fails if more than 0.01% of the pixels differ). It then draws the same frame with
// dyncull's own part renderer (a second engine on the same context): its shading is
// dyncull's, but its surfaces must be the game's, so the depth buffers must agree (again
// at most 0.01% of the pixels apart).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include <epoxy/egl.h>  // epoxy dispatches both EGL and GL
#include <epoxy/gl.h>
#define STB_IMAGE_WRITE_IMPLEMENTATION
#include <stb_image_write.h>

#include <dyncull/bsp/local_bsp.hpp>
#include <dyncull/engine/engine.hpp>
#include <dyncull/engine/heap_tuning.hpp>

namespace {

constexpr int kWidth = 480, kHeight = 270;

[[noreturn]] void fail(const std::string& why) {
    std::fprintf(stderr, "headless_game: %s\n", why.c_str());
    std::exit(1);
}

// --- The game's own context and framebuffer (nothing of dyncull here) ---------------------

void createContext() {
    EGLDisplay dpy = eglGetPlatformDisplayEXT(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr);
    if (dpy == EGL_NO_DISPLAY || !eglInitialize(dpy, nullptr, nullptr)) fail("no EGL surfaceless display");
    eglBindAPI(EGL_OPENGL_API);
    const EGLint attribs[] = {EGL_CONTEXT_MAJOR_VERSION, 4, EGL_CONTEXT_MINOR_VERSION, 5,
                              EGL_CONTEXT_OPENGL_PROFILE_MASK, EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT, EGL_NONE};
    EGLContext ctx = eglCreateContext(dpy, EGL_NO_CONFIG_KHR, EGL_NO_CONTEXT, attribs);
    if (ctx == EGL_NO_CONTEXT || !eglMakeCurrent(dpy, EGL_NO_SURFACE, EGL_NO_SURFACE, ctx)) fail("no OpenGL 4.5 context");
}

GLuint createFramebuffer() {
    GLuint colour = 0, depth = 0, fbo = 0;
    glCreateRenderbuffers(1, &colour);
    glNamedRenderbufferStorage(colour, GL_RGBA8, kWidth, kHeight);
    glCreateRenderbuffers(1, &depth);
    glNamedRenderbufferStorage(depth, GL_DEPTH_COMPONENT32F, kWidth, kHeight);  // float depth for reversed Z
    glCreateFramebuffers(1, &fbo);
    glNamedFramebufferRenderbuffer(fbo, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, colour);
    glNamedFramebufferRenderbuffer(fbo, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, depth);
    return fbo;
}

GLuint compileProgram() {
    const char* vs = R"(#version 450 core
layout(location = 0) in vec3 aPos;
layout(location = 1) in vec3 aNormal;
layout(location = 2) in vec3 aColour;
uniform mat4 uViewProj, uModel;
out vec3 vColour;
void main() {
    vec3 n = normalize(mat3(uModel) * aNormal);
    vColour = aColour * (0.35 + 0.65 * max(dot(n, normalize(vec3(0.4, 0.8, 0.6))), 0.0));
    gl_Position = uViewProj * uModel * vec4(aPos, 1.0);
})";
    const char* fs = R"(#version 450 core
in vec3 vColour;
out vec4 fragColour;
void main() { fragColour = vec4(vColour, 1.0); })";
    auto stage = [](GLenum type, const char* src) {
        GLuint s = glCreateShader(type);
        glShaderSource(s, 1, &src, nullptr);
        glCompileShader(s);
        return s;
    };
    GLuint p = glCreateProgram();
    glAttachShader(p, stage(GL_VERTEX_SHADER, vs));
    glAttachShader(p, stage(GL_FRAGMENT_SHADER, fs));
    glLinkProgram(p);
    GLint ok = 0;
    glGetProgramiv(p, GL_LINK_STATUS, &ok);
    if (!ok) fail("shader did not link");
    return p;
}

// --- The game's meshes: a torus and a wall, with a colour per vertex ----------------------

struct GameMesh {
    dyncull::Mesh shape;          // positions, normals, indices: what dyncull needs
    std::vector<float> colours;   // the game's own attribute, 3 floats per vertex
};

GameMesh torus(float major, float minor, int rings, int sides) {
    GameMesh m;
    for (int i = 0; i <= rings; ++i)
        for (int j = 0; j <= sides; ++j) {
            const float u = 6.2831853f * float(i) / float(rings), v = 6.2831853f * float(j) / float(sides);
            const glm::vec3 centre(major * std::cos(u), major * std::sin(u), 0.0f);
            const glm::vec3 n(std::cos(v) * std::cos(u), std::cos(v) * std::sin(u), std::sin(v));
            m.shape.positions.push_back(centre + minor * n);
            m.shape.normals.push_back(n);
            const bool stripe = (i / 4 + j / 4) % 2 == 0;  // a checker the split must carry through
            m.colours.insert(m.colours.end(), {stripe ? 0.95f : 0.2f, 0.55f, stripe ? 0.2f : 0.9f});
        }
    for (int i = 0; i < rings; ++i)
        for (int j = 0; j < sides; ++j) {
            const std::uint32_t a = i * (sides + 1) + j, b = a + sides + 1;
            m.shape.indices.insert(m.shape.indices.end(), {a, b, a + 1, a + 1, b, b + 1});
        }
    return m;
}

GameMesh wall(float w, float h) {
    GameMesh m;
    m.shape.positions = {{-w, -h, 0}, {w, -h, 0}, {w, h, 0}, {-w, h, 0}};
    m.shape.normals.assign(4, {0, 0, 1});
    m.shape.indices = {0, 1, 2, 0, 2, 3, 0, 2, 1, 0, 3, 2};  // both sides
    m.colours = {0.7f, 0.7f, 0.72f, 0.6f, 0.6f, 0.62f, 0.7f, 0.7f, 0.72f, 0.6f, 0.6f, 0.62f};
    return m;
}

// The game's GPU copy of a model: dyncull's split positions/normals/indices, with the
// game's colours carried through the split.
struct GpuModel {
    GLuint vao = 0;
    std::uint32_t indexCount = 0;
};

GpuModel upload(const dyncull::LocalBsp& bsp, const std::vector<float>& colours) {
    auto carried = dyncull::carryAttributes(bsp, colours, 3);
    if (!carried) fail(carried.error().message);
    std::vector<float> vertices;  // position, normal, colour
    for (std::size_t v = 0; v < bsp.mesh.positions.size(); ++v) {
        const glm::vec3 p = bsp.mesh.positions[v], n = bsp.mesh.normals[v];
        vertices.insert(vertices.end(), {p.x, p.y, p.z, n.x, n.y, n.z});
        vertices.insert(vertices.end(), carried->begin() + 3 * v, carried->begin() + 3 * v + 3);
    }
    GLuint vbo = 0, ibo = 0;
    GpuModel g;
    glCreateBuffers(1, &vbo);
    glNamedBufferStorage(vbo, GLsizeiptr(vertices.size() * sizeof(float)), vertices.data(), 0);
    glCreateBuffers(1, &ibo);
    glNamedBufferStorage(ibo, GLsizeiptr(bsp.mesh.indices.size() * 4), bsp.mesh.indices.data(), 0);
    glCreateVertexArrays(1, &g.vao);
    glVertexArrayVertexBuffer(g.vao, 0, vbo, 0, 9 * sizeof(float));
    glVertexArrayElementBuffer(g.vao, ibo);
    for (GLuint a = 0; a < 3; ++a) {
        glEnableVertexArrayAttrib(g.vao, a);
        glVertexArrayAttribFormat(g.vao, a, 3, GL_FLOAT, GL_FALSE, a * 3 * sizeof(float));
        glVertexArrayAttribBinding(g.vao, a, 0);
    }
    g.indexCount = std::uint32_t(bsp.mesh.indices.size());
    return g;
}

}  // namespace

int main(int argc, char** argv) {
    // The game's choice, not the library's: on llvmpipe, keep the heap that each draw reuses.
    dyncull::keepFreedHeapMemory();
    int frames = 30;
    std::string screenshot = "headless_game.png", cull = "full";
    bool check = false;
    for (int i = 1; i < argc; ++i) {
        const std::string a = argv[i];
        if (a == "--frames" && i + 1 < argc) frames = std::atoi(argv[++i]);
        else if (a == "--screenshot" && i + 1 < argc) screenshot = argv[++i];
        else if (a == "--cull" && i + 1 < argc) cull = argv[++i];
        else if (a == "--check") check = true;
        else fail("usage: headless_game [--frames N] [--screenshot FILE.png] [--cull none|vfc|full|queries] [--check]");
    }
    if (frames < 1) fail("--frames must be at least 1");

    createContext();
    const GLuint fbo = createFramebuffer();
    const GLuint program = compileProgram();
    const GLint locViewProj = glGetUniformLocation(program, "uViewProj"), locModel = glGetUniformLocation(program, "uModel");

    // dyncull borrows the current context; the game keeps drawing (no part renderer).
    auto gl = dyncull::GlContext::borrowCurrent();
    if (!gl) fail(gl.error().message);
    dyncull::EngineOptions options;
    options.partRenderer = false;
    if (cull != "none") {
        auto mode = dyncull::parseCullMode(cull);
        if (!mode) fail(mode.error().message);
        options.scheduler.mode = *mode;
    }
    auto made = dyncull::Engine::create(**gl, options);
    if (!made) fail(made.error().message);
    dyncull::Engine& engine = **made;

    const GameMesh ring = torus(0.6f, 0.22f, 48, 16), screen = wall(6.0f, 1.6f);
    dyncull::LocalBspParams split;
    split.maxLeafTriangles = 256;  // a few parts per torus, so parts of one ring cull too
    auto ringModel = engine.addModel(ring.shape, split);
    auto wallModel = engine.addModel(screen.shape);
    if (!ringModel || !wallModel) fail(!ringModel ? ringModel.error().message : wallModel.error().message);
    std::vector<GpuModel> gpu(2);
    gpu[*ringModel] = upload(engine.model(*ringModel), ring.colours);
    gpu[*wallModel] = upload(engine.model(*wallModel), screen.colours);

    // A wall with rings behind it and in front of it, all turning.
    struct Ring {
        dyncull::ObjectHandle handle;
        glm::vec3 home;
        float phase;
    };
    std::vector<Ring> rings;
    for (int z = 0; z < 6; ++z)
        for (int x = 0; x < 10; ++x) {
            const glm::vec3 home(-6.75f + 1.5f * float(x), -0.4f + 0.8f * float(z % 2), 2.0f - 2.0f * float(z));
            auto h = engine.addObject(*ringModel, dyncull::Transform{home});
            if (!h) fail(h.error().message);
            rings.push_back({*h, home, 0.37f * float(x + 10 * z)});
        }
    auto wallObject = engine.addObject(*wallModel, dyncull::Transform{{0, 0, 0.9f}}, /*isStatic=*/true);
    if (!wallObject) fail(wallObject.error().message);

    dyncull::Camera camera;
    camera.position = {0.0f, 1.2f, 9.0f};
    camera.target = {0.0f, 0.0f, -2.0f};
    camera.aspect = float(kWidth) / float(kHeight);
    if (dyncull::Status s = engine.setCamera(camera); !s) fail(s.message());

    const glm::mat4 viewProj = camera.viewProjection();
    auto drawPart = [&](dyncull::ModelId model, std::uint32_t first, std::uint32_t count, const glm::mat4& objectToWorld) {
        glUniformMatrix4fv(locModel, 1, GL_FALSE, &objectToWorld[0][0]);
        glBindVertexArray(gpu[model].vao);
        glDrawElements(GL_TRIANGLES, GLsizei(count), GL_UNSIGNED_INT, reinterpret_cast<const void*>(std::uintptr_t{first} * 4));
    };
    engine.setDrawCallback([&](dyncull::ObjectHandle, dyncull::ModelId model, std::uint32_t first, std::uint32_t count,
                               const glm::mat4& objectToWorld) {
        glUseProgram(program);
        glUniformMatrix4fv(locViewProj, 1, GL_FALSE, &viewProj[0][0]);
        drawPart(model, first, count, objectToWorld);
    });

    // Everything, whole, with the state dyncull's frame contract sets for its callback.
    auto drawEverything = [&] {
        glClipControl(GL_LOWER_LEFT, GL_ZERO_TO_ONE);
        glEnable(GL_DEPTH_TEST);
        glDepthFunc(GL_GREATER);
        glUseProgram(program);
        glUniformMatrix4fv(locViewProj, 1, GL_FALSE, &viewProj[0][0]);
        const dyncull::SceneObjects& objects = engine.objects();
        for (std::uint32_t i = 0; i < objects.slotCount(); ++i)
            if (objects.alive(i)) drawPart(objects.modelOf(i), 0, gpu[objects.modelOf(i)].indexCount, objects.matrix(i));
        return objects.objectCount();
    };
    auto clearFrame = [&] {
        glBindFramebuffer(GL_FRAMEBUFFER, fbo);
        glViewport(0, 0, kWidth, kHeight);
        glClearColor(0.08f, 0.09f, 0.12f, 1.0f);
        glClearDepth(0.0);  // reversed Z: 0 is the far plane
        glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
    };
    auto readDepth = [&] {
        std::vector<float> depth(std::size_t{kWidth} * kHeight);
        glBindFramebuffer(GL_READ_FRAMEBUFFER, fbo);
        glReadPixels(0, 0, kWidth, kHeight, GL_DEPTH_COMPONENT, GL_FLOAT, depth.data());
        return depth;
    };
    auto readFrame = [&] {
        std::vector<unsigned char> rgba(std::size_t{kWidth} * kHeight * 4);
        glBindFramebuffer(GL_READ_FRAMEBUFFER, fbo);
        glReadPixels(0, 0, kWidth, kHeight, GL_RGBA, GL_UNSIGNED_BYTE, rgba.data());
        return rgba;
    };

    std::size_t drawnParts = 0;
    for (int frame = 0; frame < frames; ++frame) {
        for (Ring& r : rings) {
            const float a = r.phase + 0.05f * float(frame);
            dyncull::Transform t{r.home + glm::vec3(0.3f * std::cos(a), 0.3f * std::sin(a), 0.0f)};
            t.rotation = glm::angleAxis(a, glm::vec3(0.0f, 1.0f, 0.0f));
            if (dyncull::Status s = engine.setTransform(r.handle, t); !s) fail(s.message());
        }
        // The game's frame: its framebuffer, its clear; then dyncull culls and calls back.
        clearFrame();
        if (cull == "none") {
            drawnParts += drawEverything();
        } else {
            auto stats = engine.renderFrame();
            if (!stats) fail(stats.error().message);
            drawnParts += engine.visibleParts().size();
        }
    }

    const std::vector<unsigned char> rgba = readFrame();
    stbi_flip_vertically_on_write(1);
    if (!stbi_write_png(screenshot.c_str(), kWidth, kHeight, 4, rgba.data(), kWidth * 4)) fail("cannot write " + screenshot);
    std::printf("headless_game: %d frames, cull %s, %.1f parts drawn a frame, %zu visible objects in the last; wrote %s\n",
                frames, cull.c_str(), double(drawnParts) / frames, cull == "none" ? rings.size() + 1 : engine.visibleObjects().size(),
                screenshot.c_str());
    if (check) {
        clearFrame();
        drawEverything();
        const std::vector<unsigned char> reference = readFrame();
        std::size_t differ = 0;
        for (std::size_t i = 0; i < rgba.size(); i += 4) differ += std::memcmp(&rgba[i], &reference[i], 4) != 0;
        const double percent = 100.0 * double(differ) / double(kWidth * kHeight);
        std::printf("check: %zu of %d pixels (%.4f%%) differ from drawing every object\n", differ, kWidth * kHeight, percent);
        if (percent > 0.01) return 1;

        // The same frame through dyncull's own renderer: the same models, placements and camera.
        dyncull::EngineOptions ownOptions;
        ownOptions.scheduler = options.scheduler;
        auto own = dyncull::Engine::create(**gl, ownOptions);
        if (!own) fail(own.error().message);
        auto ownRing = (*own)->addModel(ring.shape, split);
        auto ownWall = (*own)->addModel(screen.shape);
        if (!ownRing || !ownWall) fail("own renderer: cannot add the models");
        const dyncull::SceneObjects& objects = engine.objects();
        for (std::uint32_t i = 0; i < objects.slotCount(); ++i) {
            if (!objects.alive(i)) continue;
            const dyncull::ModelId model = objects.modelOf(i) == *ringModel ? *ownRing : *ownWall;
            if (auto h = (*own)->addObject(model, objects.transform(i)); !h) fail(h.error().message);
        }
        if (dyncull::Status s = (*own)->setCamera(camera); !s) fail(s.message());
        clearFrame();
        if (cull == "none") drawEverything();
        else if (auto st = engine.renderFrame(); !st) fail(st.error().message);
        const std::vector<float> gameDepth = readDepth();
        clearFrame();
        if (auto st = (*own)->renderFrame(); !st) fail(st.error().message);
        const std::vector<float> ownDepth = readDepth();
        // The game transforms in world space, dyncull relative to the eye: a few float
        // roundings apart at most.
        std::size_t depthDiffer = 0;
        for (std::size_t i = 0; i < gameDepth.size(); ++i)
            depthDiffer += std::abs(gameDepth[i] - ownDepth[i]) > 1e-5f * std::max(gameDepth[i], ownDepth[i]);
        const double depthPercent = 100.0 * double(depthDiffer) / double(kWidth * kHeight);
        std::printf("check: %zu of %d pixels (%.4f%%) differ in depth from dyncull's own renderer\n", depthDiffer,
                    kWidth * kHeight, depthPercent);
        if (depthPercent > 0.01) return 1;
    }
    return 0;
}
