// Minimal reproduction, with no dyncull code, of heap corruption in Mesa llvmpipe when a
// program polls occlusion queries in a tight loop and reuses the query objects at once.
//
// Each round: begin a query, draw a few triangles, end it, flush (one llvmpipe "scene"
// per query, as a stop-and-wait culler does), then spin on GL_QUERY_RESULT_AVAILABLE.
// llvmpipe's rasteriser threads signal a scene's fence by incrementing its counter under
// the fence's mutex and then broadcasting its condition variable; the polling thread reads
// the counter without the mutex, so it can see the fence complete, recycle the scene and
// re-begin the query (dropping the fence's last references, which frees it) while the
// signalling thread is still inside cnd_broadcast / mtx_unlock on the freed memory. The
// window is a few instructions unless the signalling thread is preempted there, which the
// busy-polling thread makes likely on a machine with as many cores as llvmpipe threads.
//
// Build: g++ -O2 -o mesa_fence_race mesa_fence_race.cpp $(pkg-config --cflags --libs epoxy egl)
// Run:   LP_NUM_THREADS=8 MALLOC_PERTURB_=165 ./mesa_fence_race [rounds] [1: delete each answered query, 0: reuse after 63 more]
// or under valgrind (memcheck reports writes into a freed block inside swrast_dri.so).
#include <epoxy/egl.h>
#include <epoxy/gl.h>

#include <cstdio>
#include <cstdlib>
#include <vector>

namespace {

bool fail(const char* what) {
    std::fprintf(stderr, "mesa_fence_race: %s failed (EGL 0x%x)\n", what, eglGetError());
    return false;
}

bool makeContext() {
    EGLDisplay dpy = eglGetPlatformDisplayEXT(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr);
    if (dpy == EGL_NO_DISPLAY) return fail("eglGetPlatformDisplayEXT(surfaceless)");
    if (!eglInitialize(dpy, nullptr, nullptr)) return fail("eglInitialize");
    if (!eglBindAPI(EGL_OPENGL_API)) return fail("eglBindAPI");
    const EGLint attribs[] = {EGL_CONTEXT_MAJOR_VERSION, 4, EGL_CONTEXT_MINOR_VERSION, 5,
                              EGL_CONTEXT_OPENGL_PROFILE_MASK, EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT, EGL_NONE};
    EGLContext ctx = eglCreateContext(dpy, EGL_NO_CONFIG_KHR, EGL_NO_CONTEXT, attribs);
    if (ctx == EGL_NO_CONTEXT) return fail("eglCreateContext");
    if (!eglMakeCurrent(dpy, EGL_NO_SURFACE, EGL_NO_SURFACE, ctx)) return fail("eglMakeCurrent");
    return true;
}

GLuint program() {
    const char* vs = "#version 450\nlayout(location=0) in vec2 p; void main(){ gl_Position = vec4(p, 0.5, 1.0); }";
    const char* fs = "#version 450\nout vec4 c; void main(){ c = vec4(1.0); }";
    GLuint p = glCreateProgram();
    for (auto [type, src] : {std::pair{GL_VERTEX_SHADER, vs}, std::pair{GL_FRAGMENT_SHADER, fs}}) {
        GLuint s = glCreateShader(type);
        glShaderSource(s, 1, &src, nullptr);
        glCompileShader(s);
        glAttachShader(p, s);
    }
    glLinkProgram(p);
    return p;
}

}  // namespace

int main(int argc, char** argv) {
    const long rounds = argc > 1 ? std::atol(argv[1]) : 200000;
    const bool reuseAtOnce = argc > 2 ? std::atoi(argv[2]) != 0 : true;
    if (!makeContext()) return 2;

    GLuint colour = 0, depth = 0, fbo = 0;
    glCreateRenderbuffers(1, &colour);
    glNamedRenderbufferStorage(colour, GL_RGBA8, 640, 360);
    glCreateRenderbuffers(1, &depth);
    glNamedRenderbufferStorage(depth, GL_DEPTH_COMPONENT32F, 640, 360);
    glCreateFramebuffers(1, &fbo);
    glNamedFramebufferRenderbuffer(fbo, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, colour);
    glNamedFramebufferRenderbuffer(fbo, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, depth);
    glBindFramebuffer(GL_FRAMEBUFFER, fbo);
    glViewport(0, 0, 640, 360);
    glEnable(GL_DEPTH_TEST);

    // A few triangles spread over the screen so every rasteriser thread gets bins.
    std::vector<float> tri;
    for (int i = 0; i < 64; ++i) {
        const float x = -1.0f + 2.0f * static_cast<float>(i % 8) / 8.0f, y = -1.0f + 2.0f * static_cast<float>(i / 8) / 8.0f;
        tri.insert(tri.end(), {x, y, x + 0.25f, y, x, y + 0.25f});
    }
    GLuint vbo = 0, vao = 0;
    glCreateBuffers(1, &vbo);
    glNamedBufferStorage(vbo, static_cast<GLsizeiptr>(tri.size() * sizeof(float)), tri.data(), 0);
    glCreateVertexArrays(1, &vao);
    glVertexArrayVertexBuffer(vao, 0, vbo, 0, 2 * sizeof(float));
    glVertexArrayAttribFormat(vao, 0, 2, GL_FLOAT, GL_FALSE, 0);
    glVertexArrayAttribBinding(vao, 0, 0);
    glEnableVertexArrayAttrib(vao, 0);
    glBindVertexArray(vao);
    glUseProgram(program());

    // Query objects: deleted as soon as answered (reuse 1), or reused only after 63 later
    // queries have answered (reuse 0).
    constexpr int kPool = 64;
    GLuint queries[kPool];
    glCreateQueries(GL_ANY_SAMPLES_PASSED_CONSERVATIVE, kPool, queries);
    unsigned long long visible = 0;
    for (long r = 0; r < rounds; ++r) {
        GLuint q = queries[r % kPool];
        if (reuseAtOnce) glCreateQueries(GL_ANY_SAMPLES_PASSED_CONSERVATIVE, 1, &q);
        if (r % 2 == 0) glClear(GL_DEPTH_BUFFER_BIT | GL_COLOR_BUFFER_BIT);
        glBeginQuery(GL_ANY_SAMPLES_PASSED_CONSERVATIVE, q);
        glDrawArrays(GL_TRIANGLES, 0, static_cast<GLsizei>(tri.size() / 2));
        glEndQuery(GL_ANY_SAMPLES_PASSED_CONSERVATIVE);
        glFlush();
        GLuint available = 0;
        while (!available) glGetQueryObjectuiv(q, GL_QUERY_RESULT_AVAILABLE, &available);
        GLuint v = 0;
        glGetQueryObjectuiv(q, GL_QUERY_RESULT, &v);
        visible += v;
        // Deleting the answered query drops its reference to the scene's fence at once.
        if (reuseAtOnce) glDeleteQueries(1, &q);
        if (r % 20000 == 0) std::printf("round %ld\n", r), std::fflush(stdout);
    }
    std::printf("done: %ld rounds, %llu visible\n", rounds, visible);
    return 0;
}
