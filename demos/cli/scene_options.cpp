#include "scene_options.hpp"

#include <map>

namespace dyncull::cli {

void addBunnyOptions(CLI::App& cmd, BunnySwarmOptions& o) {
    cmd.add_option("--count", o.count, "bunnies: number of bunnies (at most 100,000: about 35 MB of scene state)")
        ->check(wholeIn(1, kMaxBunnies))
        ->capture_default_str();
    cmd.add_option("--box", o.box, "bunnies: side of the box they move in (world units)")
        ->check(realIn(0.0, 1e6, true))
        ->capture_default_str();
    cmd.add_option("--bunny-size", o.bunnySize, "bunnies: longest side of one bunny (world units)")
        ->check(realIn(0.0, 1e5, true))
        ->capture_default_str();
    cmd.add_option("--leaf-tris", o.leafTriangles, "bunnies: local-BSP leaf size in triangles (smaller: finer culling, more queries)")
        ->check(wholeIn(1, kMaxTriangleCount))
        ->capture_default_str();
    cmd.add_option("--speed", o.speed, "bunnies: speed in world units per frame")->check(realIn(0.0, 1e4))->capture_default_str();
    cmd.add_option("--seed", o.seed, "bunnies: seed of start positions, velocities and orientations")
        ->check(wholeIn(0, kMaxSeed))
        ->capture_default_str();
    cmd.add_option("--orbit", o.orbit, "bunnies: orbit the box at this distance instead of the default flight")
        ->check(realIn(0.0, 1e7, true));
    cmd.add_option("--mesh", o.meshPath, "bunnies: mesh file to use instead of the asset directory's bunny");
    cmd.add_option("--assets", o.assetsDir, "bunnies: asset directory (default $DYNCULL_ASSETS, else ./assets)");
    cmd.add_option("--path-frames", o.frames, "bunnies: frames of one pass of the camera path")
        ->check(wholeIn(1, kMaxFrames))
        ->capture_default_str();
    cmd.add_option("--faces", o.faces,
                   "bunnies: auto (cull back faces only if the surface is closed and outward), cull (always: holes "
                   "show through) or two-sided")
        ->transform(CLI::CheckedTransformer(std::map<std::string, FacePolicy>{{"auto", FacePolicy::Auto},
                                                                              {"cull", FacePolicy::CullBack},
                                                                              {"two-sided", FacePolicy::TwoSided}}))
        ->default_str("auto");
    cmd.add_flag("--keep-holes", o.keepHoles,
                 "bunnies: keep the mesh's holes open (by default the scanned bunny's base is capped, so it is closed)");
}

void addMeasureOptions(CLI::App& cmd, MeasureOptions& o, std::string& size, const std::string& defaultOut) {
    cmd.add_option("--frames", o.frames, "frames to measure")->check(wholeIn(1, kMaxFrames))->capture_default_str();
    cmd.add_option("--first", o.firstFrame, "path frame of the first measured frame")
        ->check(wholeIn(0, kMaxFrames))
        ->capture_default_str();
    cmd.add_option("--stride", o.stride,
                   "measure every Nth frame of the path (the camera and objects move N times farther between "
                   "measured frames, so visibility history has less coherence to use)")
        ->check(wholeIn(1, 1000))
        ->capture_default_str();
    cmd.add_option("--size", size, "framebuffer size WxH")->capture_default_str();
    cmd.add_option("--out", o.out, "output directory (default " + defaultOut + ")");
    cmd.add_flag("--quiet", o.quiet, "no progress lines");
    cmd.add_option("--passes", o.passes,
                   "run the frames this many times, each from a fresh scene, engine and schedulers, and keep each mode's "
                   "least time per frame (quieter per-frame ratios on a noisy machine)")
        ->check(wholeIn(1, 100))
        ->capture_default_str();
    cmd.add_flag("--volume-bound", o.volumeBound,
                 "also query every part's box and auto volume against each frame's final depth (untimed): the parts a "
                 "conservative query-based mode must draw even with perfect order and no history; and every cluster box, with its samples");
    cmd.add_option("--bound-budget", o.boundBudgetPercent,
                   "with --volume-bound: the error budget, in % of the frame's pixels, that the cluster bound spends on box "
                   "samples")
        ->check(realIn(0.0, 100.0, true))->capture_default_str();
    addBunnyOptions(cmd, o.sceneOptions.bunny);
    addGeneratedSceneOptions(cmd, o.sceneOptions);
}

void addGeneratorOptions(CLI::App& cmd, SceneOptions& o) {
    cmd.add_option("--plant-seed", o.plant.seed, "powerplant: generator seed")->check(wholeIn(0, kMaxSeed))->capture_default_str();
    cmd.add_option("--plant-size", o.plant.size, "powerplant: fraction of the objects, (0, 1]")
        ->check(realIn(0.0, 1.0, true))
        ->capture_default_str();
    cmd.add_option("--plant-detail", o.plant.detail, "powerplant: tessellation factor, (0, 1]")
        ->check(realIn(0.0, 1.0, true))
        ->capture_default_str();
    cmd.add_option("--city-seed", o.city.seed, "city: generator seed")->check(wholeIn(0, kMaxSeed))->capture_default_str();
    cmd.add_option_function<std::uint32_t>(
        "--city-blocks", [&o](const std::uint32_t& n) { o.city.blocksX = o.city.blocksZ = n; },
        "city: blocks along each axis (default 20, at most 100)")
        ->check(wholeIn(1, 100));
}

void addGeneratedSceneOptions(CLI::App& cmd, SceneOptions& o) {
    cmd.add_option("--scene-dir", o.sceneDir, "powerplant: load every .ply/.obj under this directory instead of generating");
    cmd.add_option("--cache-dir", o.cache.dir, "powerplant/city: cache directory (default $DYNCULL_CACHE, else out/cache)");
    cmd.add_flag("--no-cache", [&o](std::int64_t) { o.cache.enabled = false; }, "powerplant/city: always regenerate, never cache");
    addGeneratorOptions(cmd, o);
    cmd.add_option_function<unsigned>(
        "--threads", [&o](const unsigned& n) { o.plant.threads = o.city.threads = o.subdivide.threads = n; },
        "powerplant/city: threads for the local BSP builds and --subdivide (default 2)")
        ->check(wholeIn(1, kMaxThreads));
    cmd.add_option("--subdivide", o.subdivide.method,
                   "static scenes: cut the whole model into objects first: phbvo, dbvs, octree or grid");
    cmd.add_option("--max-tris", o.subdivide.maxTriangles, "--subdivide: maximum triangles per leaf (object)")
        ->check(wholeIn(1, kMaxTriangleCount))
        ->capture_default_str();
    cmd.add_option("--collapse", o.subdivide.collapseTo, "--subdivide: at most this many children per node (0 keeps the tree)")
        ->check(wholeIn(0, 1000000))
        ->capture_default_str();
    cmd.add_option("--memory-mb", o.stream.memoryMb,
                   "stream the geometry under this main-memory budget: a .dnodes file, or powerplant/city (preprocessed "
                   "out of core on first use and cached)")
        ->check(wholeIn(1, 1 << 20));
    cmd.add_option("--gpu-memory-mb", o.stream.gpuMemoryMb, "streaming: GL-buffer budget for leaf geometry (0: no limit)")
        ->check(wholeIn(0, 1 << 20))
        ->capture_default_str();
    cmd.add_option("--stream-late", o.stream.late,
                   "streaming: a visible leaf not in memory is waited for (wait: conservative), drawn the first frame "
                   "it is read (draw), or left to the read-ahead (skip)")
        ->check(CLI::IsMember({"wait", "draw", "skip"}))
        ->capture_default_str();
    cmd.add_option("--camera-of", o.stream.cameraOf, "streaming: fly this built-in scene's camera path (powerplant, city)")
        ->check(CLI::IsMember({"powerplant", "city"}));
    cmd.add_flag("--in-core", o.stream.inCore, "a .dnodes file read whole at start: the in-core reference of a streamed run");
}

void addSchedulerOptions(CLI::App& cmd, SchedulerFlags& f) {
    cmd.add_flag("--no-history", f.noHistory, "full: do not skip queries of recently visible nodes");
    cmd.add_flag("--no-batching", f.noBatching, "full: one query in flight at a time");
    cmd.add_flag("--no-occupancy", f.noOccupancy, "full: no occupancy-map fast accept");
    cmd.add_flag("--no-tight", f.noTight, "full: query world AABBs instead of tightened object volumes");
    cmd.add_flag("--no-draw-queries", f.noDrawQueries,
                 "full: no query on the geometry of parts drawn untested (visibility history alone decides)");
    cmd.add_option("--max-in-flight", f.maxInFlight, "full: maximum queries in flight")->check(wholeIn(1, 65536))->capture_default_str();
    cmd.add_option("--max-skip", f.maxSkip, "full: maximum frames a visible node skips its query")
        ->check(wholeIn(0, 1000))
        ->capture_default_str();
    cmd.add_option("--volume", f.volume, "full: query volume of object parts (auto picks per part)")
        ->check(CLI::IsMember({"aabb", "obb", "kdop14", "kdop18", "kdop26", "auto"}))
        ->capture_default_str();
    cmd.add_option("--auto-saving", f.autoSaving,
                   "full, --volume auto: a k-DOP replaces a part's box if it saves at least this fraction of surface area")
        ->check(realIn(0.0, 1.0))
        ->capture_default_str();
    cmd.add_option("--pixel-threshold", f.pixelThreshold,
                   "cull nodes with at most this many visible samples (0 = conservative)")
        ->check(wholeIn(0, 1000000000))
        ->capture_default_str();
    cmd.add_option("--error-budget", f.errorBudget,
                   "full: cull visible parts while the pixels they can show stay within this percentage of the frame "
                   "(the claim is in the stats; 0 = conservative)")
        ->check(realIn(0.0, 100.0))
        ->capture_default_str();
    cmd.add_option("--front-percent", f.frontPercent,
                   "simple/full: draw the front-most N% of the leaves in the frustum without queries (conservative)")
        ->check(realIn(0.0, 100.0))
        ->capture_default_str();
}

SchedulerParams toParams(const SchedulerFlags& f, CullMode mode) {
    SchedulerParams p;
    p.mode = mode;
    p.features.useHistory = !f.noHistory;
    p.features.useBatching = !f.noBatching;
    p.features.useOccupancyAccept = !f.noOccupancy;
    p.features.useTightVolumes = !f.noTight;
    p.features.useDrawQueries = !f.noDrawQueries;
    p.tuning.maxQueriesInFlight = f.maxInFlight;
    p.tuning.history.maxSkipFrames = f.maxSkip;
    p.tuning.frontPercent = f.frontPercent;
    p.approx.errorBudgetPercent = f.errorBudget;
    p.tuning.volume = parseVolumeChoice(f.volume).value();  // checked by the option's IsMember
    p.tuning.autoVolumeSaving = f.autoSaving;
    return p;
}

}  // namespace dyncull::cli
