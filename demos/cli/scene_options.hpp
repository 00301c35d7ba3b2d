// Options shared by subcommands that run a scene (run, bench, sweep): the bunny-swarm
// parameters and the scheduler's switches, registered on a CLI11 subcommand.
#pragma once

#include <limits>
#include <string>

#include <CLI/CLI.hpp>

#include "bench_runner.hpp"
#include "cli_util.hpp"
#include "dyncull/demos/demo_scene.hpp"
#include "dyncull/scheduler/query_scheduler.hpp"

namespace dyncull::cli {

/// Upper limits of the numeric options, stated in --help and enforced before anything is
/// allocated: far beyond any sensible run, small enough that a typo cannot ask for
/// terabytes or run for years.
inline constexpr std::uint64_t kMaxFrames = 10'000'000;        ///< a day of 10 ms frames
inline constexpr std::uint64_t kMaxBunnies = 100'000;          ///< ~350 bytes of scene state each
inline constexpr std::uint64_t kMaxTriangleCount = 100'000'000;  ///< per leaf limits
inline constexpr std::uint64_t kMaxThreads = 256;
inline constexpr std::uint64_t kMaxSeed = std::numeric_limits<std::uint64_t>::max();  ///< any 64-bit seed


/// Adds --count --box --bunny-size --speed --seed --orbit --mesh --assets --path-frames.
void addBunnyOptions(CLI::App& cmd, BunnySwarmOptions& o);

/// The power plant and city generators' options (seed, size, detail, blocks), shared by
/// `run`/`bench`/`sweep` (through addGeneratedSceneOptions) and `subdivide`.
void addGeneratorOptions(CLI::App& cmd, SceneOptions& o);

/// Adds the generated-scene options (power plant, city, directory scenes, cache):
/// --scene-dir --cache-dir --no-cache --plant-seed --plant-size --plant-detail --city-seed
/// --city-blocks --threads, and --subdivide --max-tris --collapse for static scenes.
void addGeneratedSceneOptions(CLI::App& cmd, SceneOptions& o);

/// What bench and sweep share: --frames --first --stride --size (into `size`, parsed by
/// the caller) --out (help names `defaultOut`) --quiet, and the scene options above.
void addMeasureOptions(CLI::App& cmd, MeasureOptions& o, std::string& size, const std::string& defaultOut);

/// Scheduler switches for `full` ablations and tuning.
struct SchedulerFlags {
    bool noHistory = false, noBatching = false, noOccupancy = false, noTight = false, noDrawQueries = false;
    std::uint32_t maxInFlight = SchedulerParams{}.tuning.maxQueriesInFlight;
    std::uint32_t maxSkip = SchedulerParams{}.tuning.history.maxSkipFrames;
    std::uint32_t pixelThreshold = 0;
    double errorBudget = 0.0;  ///< percent of the frame's pixels (full only; 0 = conservative)
    float frontPercent = 0.0f;
    std::string volume = "auto";  ///< one of aabb, obb, kdop14, kdop18, kdop26, auto (checked by CLI11)
    float autoSaving = SchedulerParams{}.tuning.autoVolumeSaving;
};
void addSchedulerOptions(CLI::App& cmd, SchedulerFlags& f);
SchedulerParams toParams(const SchedulerFlags& f, CullMode mode);

}  // namespace dyncull::cli
