// The CPU depth pyramid: building it from a 640x360 depth buffer, and testing screen
// rectangles of the sizes the swarm's parts project to (4 to 64 pixels a side) against it.
// Items per second of BM_DepthPyramidTest is rectangles tested per second. BM_ClusterTest
// is one cluster's whole test as the late pass runs it (cluster_culling.cpp): the normal
// cone, the box's footprint (ScreenProjection::boxCentres) and the pyramid at span 32, on
// boxes of 1 to 40 pixels seen through a rotated and scaled object matrix; its parts alone
// are BM_ClusterCone and BM_ClusterFootprint. BM_ClusterRecord is cluster history's record
// of one cluster at the frame's end, and BM_ClusterRecordLearned the same for a cluster whose
// footprint the late pass handed on (the pyramid alone).
#include <benchmark/benchmark.h>

#include <random>
#include <vector>

#include <glm/gtc/matrix_transform.hpp>

#include "dyncull/bsp/leaf_clusters.hpp"
#include "dyncull/scheduler/depth_pyramid.hpp"
#include "screen_projection.hpp"

namespace {

using namespace dyncull;

std::vector<float> depthBuffer(int width, int height) {
    std::mt19937 rng(3);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    std::vector<float> d(static_cast<std::size_t>(width) * static_cast<std::size_t>(height));
    for (float& v : d) v = u(rng);
    return d;
}

void BM_DepthPyramidBuild(benchmark::State& state) {
    const int w = 640, h = 360;
    const std::vector<float> depth = depthBuffer(w, h);
    DepthPyramid p;
    for (auto _ : state) {
        p.build(depth, w, h);
        benchmark::DoNotOptimize(p.texel(p.levels() - 1, 0, 0));
    }
}
BENCHMARK(BM_DepthPyramidBuild)->Unit(benchmark::kMicrosecond);

// As the scheduler builds it: the read-back buffer adopted as level 0, no copy.
void BM_DepthPyramidAdopt(benchmark::State& state) {
    const int w = 640, h = 360;
    std::vector<float> depth = depthBuffer(w, h);
    DepthPyramid p;
    for (auto _ : state) {
        p.adopt(depth, w, h);
        depth.resize(static_cast<std::size_t>(w) * static_cast<std::size_t>(h));  // a read would fill it
        benchmark::DoNotOptimize(p.texel(p.levels() - 1, 0, 0));
    }
}
BENCHMARK(BM_DepthPyramidAdopt)->Unit(benchmark::kMicrosecond);

void BM_DepthPyramidTest(benchmark::State& state) {
    const int w = 640, h = 360;
    const std::vector<float> depth = depthBuffer(w, h);
    DepthPyramid p;
    p.build(depth, w, h);
    std::mt19937 rng(5);
    std::uniform_int_distribution<int> size(4, 64), x(0, w - 1), y(0, h - 1);
    std::uniform_real_distribution<float> z(0.0f, 1.0f);
    std::vector<ScreenRect> rects(4096);
    std::vector<float> nearest(rects.size());
    for (std::size_t i = 0; i < rects.size(); ++i) {
        const int x0 = x(rng), y0 = y(rng);
        rects[i] = {x0, y0, x0 + size(rng), y0 + size(rng)};
        nearest[i] = z(rng);
    }
    std::size_t occluded = 0;
    for (auto _ : state)
        for (std::size_t i = 0; i < rects.size(); ++i) occluded += p.occluded(rects[i], nearest[i]);
    benchmark::DoNotOptimize(occluded);
    state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations()) * static_cast<std::int64_t>(rects.size()));
}
BENCHMARK(BM_DepthPyramidTest);

struct ClusterScene {
    Camera camera;
    FrameView view;
    glm::mat4 matrix{1.0f};
    std::vector<LeafCluster> clusters;
    DepthPyramid pyramid;

    ClusterScene() {
        camera.position = {0.3f, 0.2f, 8.0f};
        camera.target = {0.0f, 0.0f, 0.0f};
        view = FrameView::of(camera, 640, 360);
        matrix = glm::scale(glm::rotate(glm::mat4(1.0f), 0.6f, glm::normalize(glm::vec3(1.0f, 2.0f, 0.5f))), glm::vec3(1.5f));
        std::mt19937 rng(9);
        std::uniform_real_distribution<float> u(-2.0f, 2.0f), size(0.01f, 0.3f), d(-1.0f, 1.0f);
        clusters.resize(4096);
        for (LeafCluster& c : clusters) {
            const glm::vec3 lo(u(rng), u(rng), u(rng));
            c.box = Aabb::fromMinMax(lo, lo + glm::vec3(size(rng), size(rng), size(rng)));
            c.coneApex = c.box.center();
            c.coneAxis = glm::normalize(glm::vec3(d(rng), d(rng), d(rng)) + glm::vec3(0.0f, 0.0f, 0.01f));
            c.coneCutoff = 0.3f;
        }
        const std::vector<float> depth = depthBuffer(640, 360);
        pyramid.build(depth, 640, 360);
    }
};

void BM_ClusterCone(benchmark::State& state) {
    const ClusterScene s;
    const ObjectSpaceEye eye(s.camera, s.matrix);
    std::size_t culled = 0;
    for (auto _ : state)
        for (const LeafCluster& c : s.clusters) culled += eye.backFacing(c);
    benchmark::DoNotOptimize(culled);
    state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations()) * static_cast<std::int64_t>(s.clusters.size()));
}
BENCHMARK(BM_ClusterCone);

void BM_ClusterFootprint(benchmark::State& state) {
    const ClusterScene s;
    const ScreenProjection screen(s.view);
    const ObjectProjection object = screen.objectProjection(s.matrix);
    std::size_t inFront = 0;
    ScreenRect centres;
    float nearest = 0.0f;
    for (auto _ : state)
        for (const LeafCluster& c : s.clusters) inFront += screen.boxCentres(object, c.box, centres, nearest);
    benchmark::DoNotOptimize(inFront);
    state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations()) * static_cast<std::int64_t>(s.clusters.size()));
}
BENCHMARK(BM_ClusterFootprint);

void BM_ClusterTest(benchmark::State& state) {
    const ClusterScene s;
    const ScreenProjection screen(s.view);
    const ObjectProjection object = screen.objectProjection(s.matrix);
    const ObjectSpaceEye eye(s.camera, s.matrix);
    std::size_t culled = 0;
    ScreenRect centres;
    float nearest = 0.0f;
    for (auto _ : state)
        for (const LeafCluster& c : s.clusters)
            culled += eye.backFacing(c) ||
                      (screen.boxCentres(object, c.box, centres, nearest) && (centres.empty() || s.pyramid.occluded(centres, nearest, 32)));
    benchmark::DoNotOptimize(culled);
    state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations()) * static_cast<std::int64_t>(s.clusters.size()));
}
BENCHMARK(BM_ClusterTest);

// Cluster history's record of one cluster (cluster_history.cpp): the rough float footprint
// and the pyramid at span 16.
void BM_ClusterRecord(benchmark::State& state) {
    const ClusterScene s;
    const ScreenProjection screen(s.view);
    const glm::mat4 toClip = screen.clipMatrixOf(s.matrix);
    std::size_t hidden = 0;
    ScreenRect centres;
    float nearest = 0.0f;
    for (auto _ : state)
        for (const LeafCluster& c : s.clusters)
            hidden += screen.roughBoxDepth(toClip, c.box, centres, nearest) && (centres.empty() || s.pyramid.occluded(centres, nearest, 16));
    benchmark::DoNotOptimize(hidden);
    state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations()) * static_cast<std::int64_t>(s.clusters.size()));
}
BENCHMARK(BM_ClusterRecord);

// The record of a cluster whose footprint the late pass's tests handed on: the pyramid at
// span 16 alone.
void BM_ClusterRecordLearned(benchmark::State& state) {
    const ClusterScene s;
    const ScreenProjection screen(s.view);
    const ObjectProjection object = screen.objectProjection(s.matrix);
    std::vector<ScreenRect> centres(s.clusters.size());
    std::vector<float> nearest(s.clusters.size(), 0.0f);
    for (std::size_t i = 0; i < s.clusters.size(); ++i) screen.boxCentres(object, s.clusters[i].box, centres[i], nearest[i]);
    std::size_t hidden = 0;
    for (auto _ : state)
        for (std::size_t i = 0; i < centres.size(); ++i) hidden += centres[i].empty() || s.pyramid.occluded(centres[i], nearest[i], 16);
    benchmark::DoNotOptimize(hidden);
    state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations()) * static_cast<std::int64_t>(centres.size()));
}
BENCHMARK(BM_ClusterRecordLearned);

}  // namespace

BENCHMARK_MAIN();
