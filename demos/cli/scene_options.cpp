#include "scene_options.hpp"

namespace dyncull::cli {

void addBunnyOptions(CLI::App& cmd, BunnySwarmOptions& o) {
    cmd.add_option("--count", o.count, "bunnies: number of bunnies")->capture_default_str();
    cmd.add_option("--box", o.box, "bunnies: side of the box they move in (world units)")->capture_default_str();
    cmd.add_option("--bunny-size", o.bunnySize, "bunnies: longest side of one bunny (world units)")->capture_default_str();
    cmd.add_option("--speed", o.speed, "bunnies: speed in world units per frame")->capture_default_str();
    cmd.add_option("--seed", o.seed, "bunnies: seed of start positions, velocities and orientations")->capture_default_str();
    cmd.add_option("--orbit", o.orbit, "bunnies: orbit the box at this distance instead of the default flight");
    cmd.add_option("--mesh", o.meshPath, "bunnies: mesh file to use instead of the asset directory's bunny");
    cmd.add_option("--assets", o.assetsDir, "bunnies: asset directory (default $DYNCULL_ASSETS, else ./assets)");
    cmd.add_option("--path-frames", o.frames, "bunnies: frames of one pass of the camera path")->capture_default_str();
}

void addSchedulerOptions(CLI::App& cmd, SchedulerFlags& f) {
    cmd.add_flag("--no-history", f.noHistory, "full: do not skip queries of recently visible nodes");
    cmd.add_flag("--no-batching", f.noBatching, "full: one query in flight at a time");
    cmd.add_flag("--no-occupancy", f.noOccupancy, "full: no occupancy-map fast accept");
    cmd.add_flag("--no-tight", f.noTight, "full: query world AABBs instead of tightened object boxes");
    cmd.add_option("--max-in-flight", f.maxInFlight, "full: maximum queries in flight")->capture_default_str();
    cmd.add_option("--max-skip", f.maxSkip, "full: maximum frames a visible node skips its query")->capture_default_str();
    cmd.add_option("--pixel-threshold", f.pixelThreshold,
                   "cull nodes with at most this many visible samples (0 = conservative)")->capture_default_str();
}

SchedulerParams toParams(const SchedulerFlags& f, CullMode mode) {
    SchedulerParams p;
    p.mode = mode;
    p.useHistory = !f.noHistory;
    p.useBatching = !f.noBatching;
    p.useOccupancyAccept = !f.noOccupancy;
    p.useTightVolumes = !f.noTight;
    p.maxQueriesInFlight = f.maxInFlight;
    p.history.maxSkipFrames = f.maxSkip;
    return p;
}

}  // namespace dyncull::cli
