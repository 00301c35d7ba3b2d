// What one volume test costs on this GL: the batched raster test (QueryBackend::testVolumes)
// and one hardware occlusion query per volume, for boxes of a given screen size in front of
// a wall (every fragment passes and writes) or behind it (every fragment fails its depth
// test), and reading the depth buffer back (QueryBackend::readDepth). Each round is timed
// from a glFinish to the answers in hand, so the GL's work is
// included. Prints, per case, microseconds per volume; and the least-squares fit of a
// batch's time, `f + count * (a + b * pixels)`, that the scheduler's cost model takes.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <random>
#include <vector>

#include <CLI/CLI.hpp>
#include <epoxy/gl.h>

#include "dyncull/engine/gl_context.hpp"
#include "dyncull/engine/gl_query_backend.hpp"
#include "dyncull/engine/heap_tuning.hpp"
#include "dyncull/engine/renderer.hpp"

namespace {

using namespace dyncull;
using Clock = std::chrono::steady_clock;

constexpr int kWidth = 640, kHeight = 360;

double median(std::vector<double> v) {
    std::sort(v.begin(), v.end());
    return v[v.size() / 2];
}

Camera benchCamera() {
    Camera c;
    c.position = {0.0f, 0.0f, 3.0f};
    c.target = {0.0f, 0.0f, 0.0f};
    c.aspect = float(kWidth) / float(kHeight);
    c.nearPlane = 0.1f;
    c.farPlane = 100.0f;
    return c;
}

/// `count` boxes `side` pixels square on screen (seen at z = `z`), 0.05 deep, at random
/// places inside the view.
std::vector<QueryVolume> boxes(const Camera& cam, int side, int count, float z, std::mt19937& rng) {
    const float halfHeight = (cam.position.z - z) * std::tan(0.5f * cam.fovYRadians);  // world units at z
    const float pixel = 2.0f * halfHeight / float(kHeight);
    const float s = float(side) * pixel, halfWidth = halfHeight * cam.aspect;
    std::uniform_real_distribution<float> x(-halfWidth, halfWidth - s), y(-halfHeight, halfHeight - s);
    std::vector<QueryVolume> out;
    for (int i = 0; i < count; ++i) {
        const glm::vec3 lo(x(rng), y(rng), z);
        out.push_back(QueryVolume::fromAabb(Aabb::fromMinMax(lo, lo + glm::vec3(s, s, 0.05f))));
    }
    return out;
}

struct Case {
    int side, count;
    bool visible;
    std::vector<double> batched, queries;  // microseconds per volume, one per round
};

}  // namespace

int main(int argc, char** argv) {
    dyncull::keepFreedHeapMemory();  // as the dyncull program does
    CLI::App app{"Cost of the batched raster test and of hardware queries per volume (640x360)"};
    int rounds = 9;
    app.add_option("--rounds", rounds, "timed rounds per case (median reported)")->check(CLI::Range(1, 1000))->capture_default_str();
    std::string margin = "grow";
    app.add_option("--margin", margin,
                   "the snapping margin (GlQueryParams::snapping): grow (boxes grown across the view), ring (a strip along every "
                   "outline), none (not conservative: to measure what the margin costs)")
        ->check(CLI::IsMember({"grow", "ring", "none"}))
        ->capture_default_str();
    CLI11_PARSE(app, argc, argv);

    ContextOptions options;
    options.width = kWidth;
    options.height = kHeight;
    auto ctx = GlContext::create(options);
    if (!ctx) {
        std::fprintf(stderr, "bench_volume_tests: %s\n", ctx.error().message.c_str());
        return 1;
    }
    auto renderer = Renderer::create(**ctx);
    GlQueryParams queryParams;
    queryParams.snapping = margin == "ring" ? SnappingMargin::Ring : margin == "none" ? SnappingMargin::None : SnappingMargin::GrowBoxes;
    auto backend = GlQueryBackend::create(**ctx, queryParams);
    if (!renderer || !backend) {
        std::fprintf(stderr, "bench_volume_tests: %s\n", (!renderer ? renderer.error() : backend.error()).message.c_str());
        return 1;
    }
    // The backend reads depth from the frame's target, which an Engine frame reads from the
    // caller's state; here the context's own single-sample framebuffer is that target.
    GLint fbo = 0;
    glGetIntegerv(GL_DRAW_FRAMEBUFFER_BINDING, &fbo);
    (*backend)->setTarget({static_cast<std::uint32_t>(fbo), {0, 0, kWidth, kHeight}, true});
    Mesh wall;
    wall.name = "wall";
    const float h = 50.0f;
    wall.positions = {{-h, -h, 0}, {h, -h, 0}, {h, h, 0}, {-h, h, 0}};
    wall.normals.assign(4, {0, 0, 1});
    wall.indices = {0, 1, 2, 0, 2, 3};
    auto wallId = (*renderer)->upload(wall);
    if (!wallId) {
        std::fprintf(stderr, "bench_volume_tests: %s\n", wallId.error().message.c_str());
        return 1;
    }
    const Camera cam = benchCamera();
    std::mt19937 rng(11);

    std::vector<Case> cases;
    for (bool visible : {true, false})
        for (int side : {4, 16, 64, 256})
            for (int count : {64, 1024})
                if (side * side * count <= 64 * 64 * 1024) cases.push_back({side, count, visible, {}, {}});

    std::vector<QueryResult> answers;
    std::vector<QueryId> ids;
    std::vector<double> readMs;
    std::vector<float> depth;
    for (int round = -1; round < rounds; ++round) {  // round -1 warms the shaders up, untimed
        for (Case& c : cases) {
            const std::vector<QueryVolume> vols = boxes(cam, c.side, c.count, c.visible ? 0.5f : -0.5f, rng);
            (*ctx)->clearFramebuffer(Renderer::kClearColour);
            (*renderer)->beginFrame(cam);
            (*renderer)->drawMesh(*wallId, glm::mat4(1.0f), {0.5f, 0.5f, 0.5f});
            (*backend)->beginFrame(FrameView::of(cam, kWidth, kHeight));
            glFinish();
            auto t0 = Clock::now();
            answers.assign(vols.size(), QueryResult::NotReady);
            (*backend)->collectVolumes((*backend)->testVolumes(vols), answers, 1e5);
            const double batched = std::chrono::duration<double, std::micro>(Clock::now() - t0).count();
            glFinish();
            t0 = Clock::now();
            ids.clear();
            (*backend)->beginBatch();
            for (const QueryVolume& v : vols) ids.push_back((*backend)->issue(v));
            (*backend)->endBatch();
            for (QueryId id : ids) {
                (*backend)->wait(id, 1e5);
                (*backend)->release(id);
            }
            const double queries = std::chrono::duration<double, std::micro>(Clock::now() - t0).count();
            glFinish();
            t0 = Clock::now();
            int w = 0, hgt = 0;
            if (!(*backend)->readDepth(depth, w, hgt) || w != kWidth || hgt != kHeight) {
                std::fprintf(stderr, "bench_volume_tests: the depth buffer could not be read back\n");
                return 1;
            }
            if (round >= 0) readMs.push_back(std::chrono::duration<double, std::milli>(Clock::now() - t0).count());
            (*renderer)->endFrame();
            if (round < 0) continue;
            c.batched.push_back(batched / c.count);
            c.queries.push_back(queries / c.count);
        }
    }

    std::printf("%-8s %6s %6s %10s %14s %14s\n", "volumes", "side", "count", "pixels", "batched_us", "query_us");
    // Least squares of a batch's microseconds, count * (a + b * pixels) + f, per kind.
    for (bool visible : {true, false}) {
        double m[3][4] = {};  // normal equations of the unknowns a, b, f
        for (const Case& c : cases) {
            if (c.visible != visible) continue;
            const double px = double(c.side) * double(c.side), us = median(c.batched);
            std::printf("%-8s %6d %6d %10.0f %14.2f %14.2f\n", visible ? "visible" : "hidden", c.side, c.count, px, us, median(c.queries));
            const double row[4] = {double(c.count), double(c.count) * px, 1.0, us * double(c.count)};
            for (int i = 0; i < 3; ++i)
                for (int j = 0; j < 4; ++j) m[i][j] += row[i] * row[j];
        }
        for (int i = 0; i < 3; ++i)  // Gauss-Jordan; the cases make the system regular
            for (int r = 0; r < 3; ++r) {
                if (r == i) continue;
                const double f = m[r][i] / m[i][i];
                for (int j = 0; j < 4; ++j) m[r][j] -= f * m[i][j];
            }
        std::printf("batched test, %s volumes: %.0f us per batch + %.2f us per volume + %.3f ns per pixel\n",
                    visible ? "visible" : "hidden", m[2][3] / m[2][2], m[0][3] / m[0][0], 1000.0 * m[1][3] / m[1][1]);
    }
    std::printf("depth readback, %dx%d, pipeline idle: %.3f ms (%.2f ns per pixel)\n", kWidth, kHeight, median(readMs),
                1e6 * median(readMs) / (double(kWidth) * double(kHeight)));
    if ((*ctx)->checkErrors() != 0) {
        std::fprintf(stderr, "bench_volume_tests: GL errors\n");
        return 1;
    }
    return 0;
}
