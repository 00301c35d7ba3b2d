// Per-frame cost of the global loose BSP (relink + refit + lazy rebuild) for moving
// objects and for static ones, and its memory per object. Targets: <= 0.1 ms/frame at 300 objects,
// <= 15 ms/frame at 100,000 objects, <= 128 bytes per object.
#include <benchmark/benchmark.h>

#include <vector>

#include "dyncull/bsp/loose_bsp.hpp"
#include "dyncull/objects/motion.hpp"

using namespace dyncull;

namespace {

LocalBsp cube() {
    LocalBsp bsp;
    LocalBspNode root;
    root.box = Aabb::fromMinMax(glm::vec3(-0.5f), glm::vec3(0.5f));
    root.indexCount = 36;
    bsp.nodes.push_back(root);
    return bsp;
}

// `count` unit cubes bouncing in a box whose volume grows with the count (constant
// density), 0.3 units per frame, placed at frame 0; their handles in `handles`.
BouncingMotion bouncingCubes(std::uint32_t count, std::uint64_t seed, bool isStatic, SceneObjects& so,
                             std::vector<ObjectHandle>& handles) {
    const float half = 2.0f * std::cbrt(static_cast<float>(count));
    BouncingMotion motion(count, Aabb::fromMinMax(glm::vec3(-half), glm::vec3(half)), 0.3f, 1.0f, seed);
    const ModelId m = so.addModel(cube());
    Transform t;
    for (std::uint32_t i = 0; i < count; ++i) {
        t.translation = motion.position(i, 0);
        handles.push_back(so.addObject(m, t, isStatic).take());
    }
    return motion;
}

// Every object moves every frame (worst case: nothing is static).
void BM_LooseBspFrame(benchmark::State& state) {
    const auto count = static_cast<std::uint32_t>(state.range(0));
    SceneObjects so;
    std::vector<ObjectHandle> hs;
    const BouncingMotion motion = bouncingCubes(count, 77, false, so, hs);
    Transform t;
    LooseBsp bsp;  // default params: rebuild budget 0.5 ms per frame
    bsp.build(so);
    std::uint64_t frame = 0;
    double relinked = 0, rebuilds = 0, treeMs = 0;
    for (auto _ : state) {
        ++frame;
        state.PauseTiming();  // moving the objects is the game's cost, not the tree's
        for (std::uint32_t i = 0; i < count; ++i) {
            t.translation = motion.position(i, frame);
            (void)so.setTransform(hs[i], t);
        }
        state.ResumeTiming();
        const LooseBspFrameStats s = bsp.update(so);
        relinked += s.relinked;
        rebuilds += s.rebuilds;
        treeMs += s.updateMs;
    }
    const double frames = static_cast<double>(frame);
    state.counters["relinked/frame"] = relinked / frames;
    state.counters["rebuilds/frame"] = rebuilds / frames;
    state.counters["update_ms"] = treeMs / frames;
    state.counters["bytes/object"] = static_cast<double>(bsp.memoryBytes()) / count;
    state.counters["nodes"] = bsp.nodeCount();
    state.counters["depth"] = bsp.depth();
}
BENCHMARK(BM_LooseBspFrame)->Arg(300)->Arg(100000)->Unit(benchmark::kMillisecond);

// The same scene with every object static: nothing moves, so a frame must cost nothing
// that grows with the object count (beside BM_LooseBspFrame's moving objects).
void BM_LooseBspFrameStatic(benchmark::State& state) {
    SceneObjects so;
    std::vector<ObjectHandle> hs;
    (void)bouncingCubes(static_cast<std::uint32_t>(state.range(0)), 77, true, so, hs);
    LooseBsp bsp;
    bsp.build(so);
    double relinked = 0, treeMs = 0, frames = 0;
    for (auto _ : state) {
        const LooseBspFrameStats s = bsp.update(so);
        relinked += s.relinked;
        treeMs += s.updateMs;
        ++frames;
    }
    state.counters["relinked/frame"] = relinked / frames;
    state.counters["update_ms"] = treeMs / frames;
}
BENCHMARK(BM_LooseBspFrameStatic)->Arg(300)->Arg(100000)->Unit(benchmark::kMillisecond);

void BM_LooseBspBuild(benchmark::State& state) {
    const auto count = static_cast<std::uint32_t>(state.range(0));
    SceneObjects so;
    std::vector<ObjectHandle> hs;
    (void)bouncingCubes(count, 5, false, so, hs);
    LooseBsp bsp;
    for (auto _ : state) bsp.build(so);
    state.counters["bytes/object"] = static_cast<double>(bsp.memoryBytes()) / count;
}
BENCHMARK(BM_LooseBspBuild)->Arg(300)->Arg(100000)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
