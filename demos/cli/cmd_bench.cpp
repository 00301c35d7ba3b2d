// `dyncull bench SCENE --modes vfc,simple,full,oracle,...`: the speed-accuracy table of
// several culling modes and approximate settings, run interleaved over the same frames,
// with errors measured against an exact ID-pass ground truth and the vfc image.
#include <cstdio>
#include <memory>
#include <string>

#include "bench_runner.hpp"
#include "cli_util.hpp"
#include "commands.hpp"
#include "report_writer.hpp"
#include "scene_options.hpp"

namespace dyncull::cli {
namespace {

struct BenchOptions {
    MeasureOptions measure;
    std::string modes = "vfc,simple,full,oracle";
    std::string size = "640x360";
    std::string volume;   // --volume
    std::string volumes;  // --volumes
    float autoSaving = SchedulerParams{}.tuning.autoVolumeSaving;
};

std::string ratioText(const std::vector<ModeSummary>& s, const std::string& a, const std::string& b) {
    const int ia = findMode(s, a), ib = findMode(s, b);
    if (ia < 0 || ib < 0 || s[ib].msMean <= 0) return "n/a";
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.3f", s[ia].msMean / s[ib].msMean);
    return buf;
}

void runBench(BenchOptions o) {
    auto size = parseSize(o.size, "--size");
    if (!size) fail(size.error().message);
    o.measure.size = *size;
    auto modes = modesFromList(o.modes);
    if (!modes) fail(modes.error().message);
    if (!o.volume.empty() && !o.volumes.empty()) fail("--volume and --volumes: give one or the other");
    if (!o.volume.empty()) {
        if (Status s = setVolume(*modes, o.volume); !s) fail(s.message());
    }
    if (!o.volumes.empty()) {
        auto expanded = withVolumes(modes.take(), o.volumes);
        if (!expanded) fail(expanded.error().message);
        modes = expanded.take();
    }
    if (!(o.autoSaving >= 0.0f && o.autoSaving <= 1.0f)) fail("--auto-saving: must be in [0, 1]");
    for (ModeSpec& m : *modes) m.scheduler.tuning.autoVolumeSaving = o.autoSaving;
    if (o.measure.out.empty()) o.measure.out = "out/bench_" + o.measure.scene;
    const std::string command = commandLine();
    std::vector<ModeSummary> summary;
    if (Status s = runMeasurement(o.measure, modes.take(), command, &summary); !s) fail(s.message());
    double best = 0;
    for (const ModeSummary& s : summary)
        if (!s.volume.empty() && (best == 0 || s.msMean < best)) best = s.msMean;
    if (!o.volume.empty() || !o.volumes.empty()) {
        for (const ModeSummary& s : summary) {
            if (s.volume.empty()) continue;
            std::printf("volume %s ms=%.3f vs_best=%.3f per_frame_vs_best=%.3f culled=%.1f%% queries=%.1f occluded=%.1f "
                        "leaf_volume=%.4g leaf_area=%.4g false_negatives=%llu\n",
                        s.name.c_str(), s.msMean, best > 0 ? s.msMean / best : 0.0, s.pairedVsBest, s.pctPartsCulled, s.queries,
                        s.occluded, s.leaves.volume, s.leaves.surfaceArea,
                        static_cast<unsigned long long>(s.falseNegatives));
        }
    }
    std::printf("ratio full/vfc=%s\n", ratioText(summary, "full", "vfc").c_str());
    std::printf("ratio full/simple=%s\n", ratioText(summary, "full", "simple").c_str());
    std::printf("ratio full/oracle=%s\n", ratioText(summary, "full", "oracle").c_str());
    const int full = findMode(summary, "full");
    if (full >= 0) {
        std::printf("error full pixels=%.4f%%\n", summary[full].pctWrongMean);
        std::printf("false_negatives full=%llu\n", static_cast<unsigned long long>(summary[full].falseNegatives));
    } else {
        std::printf("error full pixels=n/a\n");
        std::printf("false_negatives full=n/a\n");
    }
}

}  // namespace

void registerBench(CLI::App& app) {
    auto o = std::make_shared<BenchOptions>();
    CLI::App* cmd = app.add_subcommand(
        "bench", "Measure culling modes and approximate settings interleaved: time, parts, queries, error vs ground truth");
    cmd->add_option("scene", o->measure.scene, "bunnies, powerplant, city, a directory of .ply/.obj parts, a model file, or a .dsub file from dyncull subdivide")
        ->capture_default_str();
    cmd->add_option("--modes", o->modes, "comma-separated modes: " + modeNamesHelp())->capture_default_str();
    cmd->add_option("--volume", o->volume,
                    "query volume of every full-based mode: aabb, obb, kdop14, kdop18, kdop26 or auto (default aabb)");
    cmd->add_option("--volumes", o->volumes,
                    "comma-separated volumes: each full-based mode runs once per volume, named MODE+VOLUME "
                    "(adds a query-volume table to report.md)");
    cmd->add_option("--auto-saving", o->autoSaving,
                    "auto volume: a k-DOP replaces a node's box if it saves at least this fraction of surface area")
        ->check(realIn(0.0, 1.0))
        ->capture_default_str();
    addMeasureOptions(*cmd, o->measure, o->size, "out/bench_<scene>");
    cmd->callback([o] { runBench(*o); });
}

}  // namespace dyncull::cli
