// The CPU depth pyramid: building it from a 640x360 depth buffer, and testing screen
// rectangles of the sizes the swarm's parts project to (4 to 64 pixels a side) against it.
// Items per second of BM_DepthPyramidTest is rectangles tested per second.
#include <benchmark/benchmark.h>

#include <random>
#include <vector>

#include "dyncull/scheduler/depth_pyramid.hpp"

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

}  // namespace

BENCHMARK_MAIN();
