// Build time of the local BSP (buildLocalBsp) on the Stanford bunny, both split methods,
// and on a procedural ~70k-triangle sphere so the benchmark always runs.
#include <benchmark/benchmark.h>

#include <cmath>
#include <filesystem>
#include <numbers>
#include <string>

#include "dyncull/bsp/local_bsp.hpp"
#include "dyncull/loaders/loaders.hpp"

namespace {

using namespace dyncull;

// UV sphere with 2 * slices * (stacks - 1) triangles.
Mesh sphereMesh(int slices, int stacks) {
    Mesh m;
    for (int j = 0; j <= stacks; ++j) {
        const float phi = std::numbers::pi_v<float> * float(j) / float(stacks);
        for (int i = 0; i < slices; ++i) {
            const float theta = 2.0f * std::numbers::pi_v<float> * float(i) / float(slices);
            m.positions.push_back({std::sin(phi) * std::cos(theta), std::cos(phi), std::sin(phi) * std::sin(theta)});
        }
    }
    for (int j = 0; j < stacks; ++j) {
        for (int i = 0; i < slices; ++i) {
            const auto a = std::uint32_t(j * slices + i), b = std::uint32_t(j * slices + (i + 1) % slices);
            const auto c = a + std::uint32_t(slices), d = b + std::uint32_t(slices);
            if (j > 0) m.indices.insert(m.indices.end(), {a, b, c});
            if (j + 1 < stacks) m.indices.insert(m.indices.end(), {b, d, c});
        }
    }
    computeNormals(m);
    return m;
}

const Mesh* bunny() {
    static const Mesh mesh = [] {
        const std::filesystem::path path = std::filesystem::path(DYNCULL_BENCH_DATA_DIR) / "bun_zipper.ply";
        if (!std::filesystem::exists(path)) return Mesh{};
        Expected<Scene> scene = loadScene(path);  // has normals, so the build does not time them
        return scene.ok() && scene->meshes.size() == 1 ? scene->meshes[0] : Mesh{};
    }();
    return mesh.indices.empty() ? nullptr : &mesh;
}

void runBuild(benchmark::State& state, const Mesh& mesh, SplitMethod method) {
    LocalBspParams params;
    params.method = method;
    LocalBspStats stats;
    for (auto _ : state) {
        Expected<LocalBsp> bsp = buildLocalBsp(mesh, params);
        if (!bsp.ok()) {
            state.SkipWithError(bsp.error().message.c_str());
            return;
        }
        stats = bsp->stats;
        benchmark::DoNotOptimize(bsp->nodes.data());
    }
    state.counters["leaves"] = double(stats.leaves);
    state.counters["tris_after"] = double(stats.trianglesAfter);
    state.counters["tri_increase_pct"] =
        100.0 * (double(stats.trianglesAfter) / double(stats.trianglesBefore) - 1.0);
    state.counters["depth"] = double(stats.depth);
}

void BM_LocalBspBunny(benchmark::State& state, SplitMethod method) {
    const Mesh* mesh = bunny();
    if (!mesh) {
        state.SkipWithError("bun_zipper.ply not found in " DYNCULL_BENCH_DATA_DIR);
        return;
    }
    runBuild(state, *mesh, method);
}

void BM_LocalBspSphere70k(benchmark::State& state, SplitMethod method) {
    static const Mesh mesh = sphereMesh(250, 141);  // 2 * 250 * 140 = 70,000 triangles
    runBuild(state, mesh, method);
}

BENCHMARK_CAPTURE(BM_LocalBspBunny, SpatialMedian, SplitMethod::SpatialMedian)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_LocalBspBunny, Sah, SplitMethod::Sah)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_LocalBspSphere70k, SpatialMedian, SplitMethod::SpatialMedian)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_LocalBspSphere70k, Sah, SplitMethod::Sah)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
