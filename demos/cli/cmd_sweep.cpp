// `dyncull sweep SCENE --param NAME=v1,v2,... [--param NAME2=...]`: speed-accuracy curves
// across parameters, one family per --param; each value is a mode, run interleaved with vfc
// (the reference image) and the oracle (the lower bound), with the same outputs as
// `dyncull bench`, and speed_vs_accuracy.png draws each family's Pareto front as a curve.
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "bench_runner.hpp"
#include "cli_util.hpp"
#include "commands.hpp"
#include "report_writer.hpp"
#include "scene_options.hpp"

namespace dyncull::cli {
namespace {

struct SweepOptions {
    MeasureOptions measure;
    std::vector<std::string> params;
    std::string size = "640x360";
};

void runSweep(SweepOptions o) {
    auto size = parseSize(o.size, "--size");
    if (!size) fail(size.error().message);
    o.measure.size = *size;
    std::vector<ModeSpec> modes;
    for (const char* name : {"vfc", "oracle"}) {
        auto m = modeFromName(name);
        modes.push_back(m.take());
    }
    for (const std::string& param : o.params) {
        auto values = sweepModes(param);
        if (!values) fail(values.error().message);
        for (ModeSpec& m : *values) {
            for (const ModeSpec& other : modes)
                if (other.name == m.name) fail("--param: '" + m.name + "' given twice");
            modes.push_back(std::move(m));
        }
    }
    if (o.measure.out.empty()) o.measure.out = "out/sweep_" + o.measure.scene;
    const std::string command = commandLine();
    std::vector<ModeSummary> summary;
    if (Status s = runMeasurement(o.measure, std::move(modes), command, &summary); !s) fail(s.message());
    for (const ModeSummary& s : summary) {
        if (s.name == "vfc" || s.oracle) continue;
        std::printf("sweep %s ms=%.3f ratio_vfc=%.3f ratio_oracle=%.3f pixels=%.4f%% false_negatives=%llu\n",
                    s.name.c_str(), s.msMean, s.ratioVfc, s.ratioOracle, s.pctWrongMean,
                    static_cast<unsigned long long>(s.falseNegatives));
    }
}

}  // namespace

void registerSweep(CLI::App& app) {
    auto o = std::make_shared<SweepOptions>();
    CLI::App* cmd = app.add_subcommand("sweep", "Speed-accuracy curves across parameters, one per --param (with vfc and oracle)");
    cmd->add_option("scene", o->measure.scene, "bunnies, powerplant, city, a directory of .ply/.obj parts, a model file, or a .dsub file from dyncull subdivide")
        ->capture_default_str();
    cmd->add_option("--param", o->params, "NAME=v1,v2,... with NAME one of " + sweepParamsHelp() + "; repeat for more families")
        ->required()
        ->allow_extra_args(false)  // one NAME=... per --param, so the scene may follow
        ->take_all();
    addMeasureOptions(*cmd, o->measure, o->size, "out/sweep_<scene>");
    cmd->callback([o] { runSweep(*o); });
}

}  // namespace dyncull::cli
