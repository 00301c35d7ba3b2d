// A windowed game that uses dyncull only to decide what to draw.
//
// The game has its own GLFW window and context, its own framebuffer (float depth, blitted
// to the window), textured meshes with their own texture coordinates, its own shader and
// its own motion: crates circling behind and in front of a long wall. dyncull borrows the
// context and calls back with the visible parts of each crate.
//
//   glfw_game [--frames N] [--screenshot FILE.png] [--check]     (N = 0: until the window closes)
//
// --check draws the last frame again without asking dyncull and compares: culling is
// conservative, so the pictures must agree (the program fails if more than 0.01% of the
// pixels differ). It then draws the same frame with dyncull's own part renderer (a second
// engine on the same context): its shading is dyncull's, but its surfaces must be the
// game's, so the depth buffers must agree (again at most 0.01% of the pixels apart).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include <epoxy/gl.h>  // before GLFW, so GLFW includes no GL header of its own
#include <GLFW/glfw3.h>
#define STB_IMAGE_WRITE_IMPLEMENTATION
#include <stb_image_write.h>

#include <dyncull/bsp/local_bsp.hpp>
#include <dyncull/engine/engine.hpp>

namespace {

constexpr int kWidth = 640, kHeight = 360;

[[noreturn]] void fail(const std::string& why) {
    std::fprintf(stderr, "glfw_game: %s\n", why.c_str());
    std::exit(1);
}

// A crate: a box of 6 x n x n quads (finer than needed, so dyncull splits it into parts),
// with texture coordinates running 0..1 over each face.
struct TexturedMesh {
    dyncull::Mesh shape;
    std::vector<float> uv;  // 2 per vertex: the game's own attribute
};

TexturedMesh crate(float half, int n) {
    TexturedMesh m;
    for (int face = 0; face < 6; ++face) {
        const int axis = face / 2;
        const float sign = face % 2 ? 1.0f : -1.0f;
        glm::vec3 normal(0.0f), u(0.0f), v(0.0f);
        normal[axis] = sign;
        u[(axis + 1) % 3] = 1.0f;
        v[(axis + 2) % 3] = 1.0f;
        if (sign < 0) std::swap(u, v);  // keep the winding counter-clockwise seen from outside
        const auto base = static_cast<std::uint32_t>(m.shape.positions.size());
        for (int i = 0; i <= n; ++i)
            for (int j = 0; j <= n; ++j) {
                const float s = float(i) / float(n), t = float(j) / float(n);
                m.shape.positions.push_back(half * (normal + (2 * s - 1) * u + (2 * t - 1) * v));
                m.shape.normals.push_back(normal);
                m.uv.insert(m.uv.end(), {s, t});
            }
        for (int i = 0; i < n; ++i)
            for (int j = 0; j < n; ++j) {
                const std::uint32_t a = base + std::uint32_t(i * (n + 1) + j), b = a + std::uint32_t(n + 1);
                m.shape.indices.insert(m.shape.indices.end(), {a, b, b + 1, a, b + 1, a + 1});
            }
    }
    return m;
}

// A procedural texture: planks with a dark border, as a game would load from a file.
GLuint crateTexture() {
    constexpr int size = 128;
    std::vector<unsigned char> texels(size * size * 4);
    for (int y = 0; y < size; ++y)
        for (int x = 0; x < size; ++x) {
            const bool border = x < 10 || y < 10 || x >= size - 10 || y >= size - 10;
            const bool seam = (y / 22) % 2 == 0 && y % 22 < 2;
            const unsigned char shade = border ? 90 : seam ? 120 : static_cast<unsigned char>(170 + (x * 7 + y * 3) % 30);
            unsigned char* t = &texels[std::size_t(y * size + x) * 4];
            t[0] = shade;
            t[1] = static_cast<unsigned char>(shade * 0.7f);
            t[2] = static_cast<unsigned char>(shade * 0.4f);
            t[3] = 255;
        }
    GLuint tex = 0;
    glCreateTextures(GL_TEXTURE_2D, 1, &tex);
    glTextureStorage2D(tex, 1, GL_RGBA8, size, size);
    glTextureSubImage2D(tex, 0, 0, 0, size, size, GL_RGBA, GL_UNSIGNED_BYTE, texels.data());
    glTextureParameteri(tex, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
    glTextureParameteri(tex, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    return tex;
}

GLuint compileProgram() {
    const char* vs = R"(#version 450 core
layout(location = 0) in vec3 aPos;
layout(location = 1) in vec3 aNormal;
layout(location = 2) in vec2 aUv;
uniform mat4 uViewProj, uModel;
out vec2 vUv;
out float vLight;
void main() {
    vLight = 0.4 + 0.6 * max(dot(normalize(mat3(uModel) * aNormal), normalize(vec3(0.3, 0.9, 0.5))), 0.0);
    vUv = aUv;
    gl_Position = uViewProj * uModel * vec4(aPos, 1.0);
})";
    const char* fs = R"(#version 450 core
in vec2 vUv;
in float vLight;
uniform sampler2D uTexture;
uniform vec3 uTint;
out vec4 fragColour;
void main() { fragColour = vec4(texture(uTexture, vUv).rgb * uTint * vLight, 1.0); })";
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

// The game's vertex array for a model: dyncull's split positions, normals and indices,
// with the game's texture coordinates carried through the split.
GLuint upload(const dyncull::LocalBsp& bsp, const std::vector<float>& uv) {
    auto carried = dyncull::carryAttributes(bsp, uv, 2);
    if (!carried) fail(carried.error().message);
    std::vector<float> vertices;
    for (std::size_t v = 0; v < bsp.mesh.positions.size(); ++v) {
        const glm::vec3 p = bsp.mesh.positions[v], n = bsp.mesh.normals[v];
        vertices.insert(vertices.end(), {p.x, p.y, p.z, n.x, n.y, n.z, (*carried)[2 * v], (*carried)[2 * v + 1]});
    }
    GLuint vbo = 0, ibo = 0, vao = 0;
    glCreateBuffers(1, &vbo);
    glNamedBufferStorage(vbo, GLsizeiptr(vertices.size() * sizeof(float)), vertices.data(), 0);
    glCreateBuffers(1, &ibo);
    glNamedBufferStorage(ibo, GLsizeiptr(bsp.mesh.indices.size() * 4), bsp.mesh.indices.data(), 0);
    glCreateVertexArrays(1, &vao);
    glVertexArrayVertexBuffer(vao, 0, vbo, 0, 8 * sizeof(float));
    glVertexArrayElementBuffer(vao, ibo);
    const GLint sizes[3] = {3, 3, 2};
    const GLuint offsets[3] = {0, 3, 6};
    for (GLuint a = 0; a < 3; ++a) {
        glEnableVertexArrayAttrib(vao, a);
        glVertexArrayAttribFormat(vao, a, sizes[a], GL_FLOAT, GL_FALSE, offsets[a] * sizeof(float));
        glVertexArrayAttribBinding(vao, a, 0);
    }
    return vao;
}

}  // namespace

int main(int argc, char** argv) {
    int frames = 0;
    std::string screenshot;
    bool check = false;
    for (int i = 1; i < argc; ++i) {
        const std::string a = argv[i];
        if (a == "--frames" && i + 1 < argc) frames = std::atoi(argv[++i]);
        else if (a == "--screenshot" && i + 1 < argc) screenshot = argv[++i];
        else if (a == "--check") check = true;
        else fail("usage: glfw_game [--frames N] [--screenshot FILE.png] [--check]");
    }
    if (frames < 0 || (check && frames == 0)) fail("--frames must be positive (and given with --check)");

    // The game's window and context.
    if (!glfwInit()) fail("no display for a window");
    glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 4);
    glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 5);
    glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
    GLFWwindow* window = glfwCreateWindow(kWidth, kHeight, "dyncull glfw_game", nullptr, nullptr);
    if (!window) fail("no OpenGL 4.5 window");
    glfwMakeContextCurrent(window);

    // Its own framebuffer with float depth (reversed Z), blitted to the window each frame.
    GLuint colour = 0, depth = 0, fbo = 0;
    glCreateRenderbuffers(1, &colour);
    glNamedRenderbufferStorage(colour, GL_RGBA8, kWidth, kHeight);
    glCreateRenderbuffers(1, &depth);
    glNamedRenderbufferStorage(depth, GL_DEPTH_COMPONENT32F, kWidth, kHeight);
    glCreateFramebuffers(1, &fbo);
    glNamedFramebufferRenderbuffer(fbo, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, colour);
    glNamedFramebufferRenderbuffer(fbo, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, depth);
    const GLuint program = compileProgram(), texture = crateTexture();
    const GLint locViewProj = glGetUniformLocation(program, "uViewProj"), locModel = glGetUniformLocation(program, "uModel"),
                locTint = glGetUniformLocation(program, "uTint");

    // dyncull borrows the window's context; the game draws every part itself.
    auto gl = dyncull::GlContext::borrowCurrent();
    if (!gl) fail(gl.error().message);
    dyncull::EngineOptions options;
    options.partRenderer = false;
    auto made = dyncull::Engine::create(**gl, options);
    if (!made) fail(made.error().message);
    dyncull::Engine& engine = **made;

    const TexturedMesh box = crate(0.5f, 12), slab = crate(1.0f, 2);
    dyncull::LocalBspParams split;
    split.maxLeafTriangles = 300;
    auto crateModel = engine.addModel(box.shape, split);
    auto wallModel = engine.addModel(slab.shape);
    if (!crateModel || !wallModel) fail(!crateModel ? crateModel.error().message : wallModel.error().message);
    std::vector<GLuint> vaos(2);
    std::vector<std::uint32_t> indexCounts(2);
    for (dyncull::ModelId m : {*crateModel, *wallModel}) {
        vaos[m] = upload(engine.model(m), m == *crateModel ? box.uv : slab.uv);
        indexCounts[m] = std::uint32_t(engine.model(m).mesh.indices.size());
    }
    dyncull::Transform wallPlace{{0.0f, 0.8f, 0.0f}};
    wallPlace.scale = {9.0f, 1.8f, 0.3f};
    if (!engine.addObject(*wallModel, wallPlace, /*isStatic=*/true)) fail("cannot add the wall");
    std::vector<dyncull::ObjectHandle> crates;
    for (int i = 0; i < 40; ++i) {
        auto h = engine.addObject(*crateModel, dyncull::Transform{});
        if (!h) fail(h.error().message);
        crates.push_back(*h);
    }

    dyncull::Camera camera;
    camera.position = {0.0f, 2.2f, 11.0f};
    camera.target = {0.0f, 0.5f, 0.0f};
    camera.aspect = float(kWidth) / float(kHeight);
    if (dyncull::Status s = engine.setCamera(camera); !s) fail(s.message());
    const glm::mat4 viewProj = camera.viewProjection();
    const std::vector<glm::vec3> tints = {{1.0f, 1.0f, 1.0f}, {0.7f, 0.7f, 0.75f}};
    auto drawPart = [&](dyncull::ModelId model, std::uint32_t first, std::uint32_t count, const glm::mat4& objectToWorld) {
        glUseProgram(program);
        glBindTextureUnit(0, texture);
        glUniformMatrix4fv(locViewProj, 1, GL_FALSE, &viewProj[0][0]);
        glUniformMatrix4fv(locModel, 1, GL_FALSE, &objectToWorld[0][0]);
        glUniform3fv(locTint, 1, &tints[model][0]);
        glBindVertexArray(vaos[model]);
        glDrawElements(GL_TRIANGLES, GLsizei(count), GL_UNSIGNED_INT, reinterpret_cast<const void*>(std::uintptr_t{first} * 4));
    };
    engine.setDrawCallback([&](dyncull::ObjectHandle, dyncull::ModelId model, std::uint32_t first, std::uint32_t count,
                               const glm::mat4& objectToWorld) { drawPart(model, first, count, objectToWorld); });

    // Everything, whole, with the state dyncull's frame contract sets for its callback.
    auto drawEverything = [&] {
        glClipControl(GL_LOWER_LEFT, GL_ZERO_TO_ONE);
        glEnable(GL_DEPTH_TEST);
        glDepthFunc(GL_GREATER);
        const dyncull::SceneObjects& objects = engine.objects();
        for (std::uint32_t i = 0; i < objects.slotCount(); ++i)
            if (objects.alive(i)) drawPart(objects.modelOf(i), 0, indexCounts[objects.modelOf(i)], objects.matrix(i));
    };
    auto clearFrame = [&] {
        glBindFramebuffer(GL_FRAMEBUFFER, fbo);
        glViewport(0, 0, kWidth, kHeight);
        glClearColor(0.45f, 0.6f, 0.8f, 1.0f);
        glClearDepth(0.0);  // reversed Z: 0 is the far plane
        glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
    };
    auto readFrame = [&] {
        std::vector<unsigned char> rgba(std::size_t{kWidth} * kHeight * 4);
        glBindFramebuffer(GL_READ_FRAMEBUFFER, fbo);
        glReadPixels(0, 0, kWidth, kHeight, GL_RGBA, GL_UNSIGNED_BYTE, rgba.data());
        return rgba;
    };
    auto readDepth = [&] {
        std::vector<float> d(std::size_t{kWidth} * kHeight);
        glBindFramebuffer(GL_READ_FRAMEBUFFER, fbo);
        glReadPixels(0, 0, kWidth, kHeight, GL_DEPTH_COMPONENT, GL_FLOAT, d.data());
        return d;
    };

    double partsDrawn = 0, partsTotal = 0;
    int frame = 0;
    for (; (frames == 0 || frame < frames) && !glfwWindowShouldClose(window); ++frame) {
        // Motion: the crates circle round the wall, half of the time hidden behind it.
        for (std::size_t i = 0; i < crates.size(); ++i) {
            const float a = 0.02f * float(frame) + 6.2831853f * float(i) / float(crates.size());
            dyncull::Transform t{{5.0f * std::cos(a), 0.2f + 0.35f * float(i % 4), 3.0f * std::sin(a)}};
            t.rotation = glm::angleAxis(1.7f * a, glm::normalize(glm::vec3(1.0f, 2.0f, 0.5f)));
            if (dyncull::Status s = engine.setTransform(crates[i], t); !s) fail(s.message());
        }
        clearFrame();
        auto stats = engine.renderFrame();
        if (!stats) fail(stats.error().message);
        partsDrawn += double(engine.visibleParts().size());
        partsTotal += double(crates.size() * engine.model(*crateModel).stats.leaves + engine.model(*wallModel).stats.leaves);
        glBlitNamedFramebuffer(fbo, 0, 0, 0, kWidth, kHeight, 0, 0, kWidth, kHeight, GL_COLOR_BUFFER_BIT, GL_NEAREST);
        glfwSwapBuffers(window);
        glfwPollEvents();
    }

    const std::vector<unsigned char> rgba = readFrame();
    if (!screenshot.empty()) {
        stbi_flip_vertically_on_write(1);
        if (!stbi_write_png(screenshot.c_str(), kWidth, kHeight, 4, rgba.data(), kWidth * 4)) fail("cannot write " + screenshot);
    }
    std::printf("glfw_game: %d frames, %.1f of %.0f parts drawn a frame, %zu visible objects in the last%s%s\n", frame,
                partsDrawn / std::max(frame, 1), partsTotal / std::max(frame, 1), engine.visibleObjects().size(),
                screenshot.empty() ? "" : "; wrote ", screenshot.c_str());
    int status = 0;
    if (check) {
        clearFrame();
        drawEverything();
        const std::vector<unsigned char> reference = readFrame();
        std::size_t differ = 0;
        for (std::size_t i = 0; i < rgba.size(); i += 4) differ += std::memcmp(&rgba[i], &reference[i], 4) != 0;
        const double percent = 100.0 * double(differ) / double(kWidth * kHeight);
        std::printf("check: %zu of %d pixels (%.4f%%) differ from drawing every object\n", differ, kWidth * kHeight, percent);
        if (percent > 0.01) status = 1;

        // The same frame through dyncull's own renderer: the same models, placements and camera.
        auto own = dyncull::Engine::create(**gl);
        if (!own) fail(own.error().message);
        auto ownCrate = (*own)->addModel(box.shape, split);
        auto ownWall = (*own)->addModel(slab.shape);
        if (!ownCrate || !ownWall) fail("own renderer: cannot add the models");
        const dyncull::SceneObjects& objects = engine.objects();
        for (std::uint32_t i = 0; i < objects.slotCount(); ++i) {
            if (!objects.alive(i)) continue;
            const dyncull::ModelId model = objects.modelOf(i) == *crateModel ? *ownCrate : *ownWall;
            if (auto h = (*own)->addObject(model, objects.transform(i)); !h) fail(h.error().message);
        }
        if (dyncull::Status s = (*own)->setCamera(camera); !s) fail(s.message());
        clearFrame();
        if (auto st = engine.renderFrame(); !st) fail(st.error().message);
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
        if (depthPercent > 0.01) status = 1;
        own->reset();
    }
    made->reset();  // the engines before the context they borrow
    gl->reset();
    glfwDestroyWindow(window);
    glfwTerminate();
    return status;
}
