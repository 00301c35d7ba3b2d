// Interleaved measurement of culling modes against ground truth (see bench_runner.hpp).
#include "bench_runner.hpp"

#include <algorithm>
#include <cassert>
#include <charconv>
#include <cstdio>
#include <filesystem>
#include <iterator>
#include <string_view>
#include <utility>

#include "dyncull/measure/budget_oracle.hpp"
#include "dyncull/measure/png_writer.hpp"
#include "dyncull/bsp/traversal.hpp"
#include "dyncull/engine/gl_context.hpp"
#include "report_writer.hpp"

namespace dyncull::cli {
namespace {

/// Whole string as an unsigned 32-bit number, or false.
bool parseU32(const std::string& s, std::uint32_t& out) {
    if (s.empty()) return false;
    const auto [p, ec] = std::from_chars(s.data(), s.data() + s.size(), out);
    return ec == std::errc() && p == s.data() + s.size();
}

/// Whole string as a plain decimal percentage in (0, 100], or false.
bool parsePercent(std::string_view s, double& out) {
    const auto [p, ec] = std::from_chars(s.data(), s.data() + s.size(), out, std::chars_format::fixed);
    return !s.empty() && ec == std::errc() && p == s.data() + s.size() && out > 0.0 && out <= 100.0;
}

/// "budget0.1" -> 0.1 for prefix "budget".
bool percentAfter(const std::string& name, const std::string& prefix, double& out) {
    return name.size() > prefix.size() && name.compare(0, prefix.size(), prefix) == 0 &&
           parsePercent(std::string_view(name).substr(prefix.size()), out);
}

/// "thr16" -> 16 for prefix "thr".
bool numberAfter(const std::string& name, const std::string& prefix, std::uint32_t& out) {
    return name.size() > prefix.size() && name.compare(0, prefix.size(), prefix) == 0 &&
           parseU32(name.substr(prefix.size()), out);
}

std::vector<std::string> splitCommas(const std::string& s) {
    std::vector<std::string> out;
    std::size_t start = 0;
    while (start <= s.size()) {
        const std::size_t comma = s.find(',', start);
        const std::size_t end = comma == std::string::npos ? s.size() : comma;
        out.push_back(s.substr(start, end - start));
        if (comma == std::string::npos) break;
        start = comma + 1;
    }
    return out;
}

ModeSpec queriesMode(const std::string& name) {
    ModeSpec m;
    m.name = name;
    m.scheduler.mode = CullMode::Queries;
    return m;
}

/// `full` and its ablations (two-phase), or false.
bool applyTwoPhaseName(const std::string& part, ModeSpec& m) {
    // full with an error budget: culls visible parts while their samples fit in it; the
    // variants hand it early-set parts that show less (budgetearly), or count the parts
    // that could fit again, last (budgetrecount). No prefix's number parses after another's.
    for (const std::string prefix : {"budget", "budgetearly", "budgetrecount"}) {
        double budget = 0.0;
        if (!percentAfter(part, prefix, budget)) continue;
        m.scheduler.mode = CullMode::TwoPhase;
        m.scheduler.approx.errorBudgetPercent = budget;
        m.scheduler.approx.budgetEarlySet = prefix == "budgetearly";
        m.scheduler.approx.budgetRecount = prefix == "budgetrecount";
        return true;
    }
    if (part != "full" && part != "full-hzb" && part != "full-nohist" && part != "full-nocost" && part != "full-tri" &&
        part != "full-noclusters" && part != "full-noclusterhist" && part != "full-markclusterhist" && part != "full-noworker" &&
        part != "full-ring" && part != "full-splitwaits" && part != "full-noroundpyramid" &&
        part != "full-nosubmit" && part != "full-testprobe" && part != "full-rasterrefresh" && part != "full-ownrecord" && part != "full-notexel" && part != "full-obbpoints" && part != "full-nolatepyramid")
        return false;
    m.scheduler.mode = CullMode::TwoPhase;
    m.scheduler.features.useBatchedRaster = part != "full-hzb";
    if (part == "full-tri") {
        // Every part whose volume passed is tested on its triangles: the design measured,
        // not the cost model's choice (which on llvmpipe tests almost none).
        m.scheduler.features.useTriangleTests = true;
        m.scheduler.tuning.costs.triangleTestNsPerPart = 0.0;
        m.scheduler.tuning.costs.triangleTestNsPerTriangle = 0.0;
    }
    m.scheduler.features.useHistory = part != "full-nohist";
    m.scheduler.features.useCostModel = part != "full-nocost";
    m.scheduler.features.useClusters = part != "full-noclusters";
    m.scheduler.features.useClusterHistory = part != "full-noclusterhist";
    m.scheduler.features.useClusterMarks = part == "full-markclusterhist";
    m.scheduler.features.useClusterWorker = part != "full-noworker";
    if (part == "full-ring") m.queries.snapping = SnappingMargin::Ring;
    m.scheduler.tuning.splitDrawWaits = part == "full-splitwaits";
    m.scheduler.features.useRoundPyramids = part != "full-noroundpyramid";
    m.scheduler.features.useObbFrames = part != "full-obbpoints";
    m.scheduler.features.useLatePyramid = part != "full-nolatepyramid";
    if (part == "full-nosubmit") m.submitTriangles = 0;
    m.scheduler.features.useEndProbes = part != "full-testprobe";
    m.scheduler.features.useRefreshPyramid = part != "full-rasterrefresh";
    m.scheduler.features.useLearnedClusters = part != "full-ownrecord";
    if (part == "full-notexel") m.scheduler.tuning.texelTestTexels = m.scheduler.tuning.clusterTexelTests = 0;
    return true;
}

}  // namespace

std::string modeNamesHelp() {
    return "vfc, simple, full (two-phase: draw last frame's visible parts, test the rest against their depth pyramid, then what it cannot reject in one batched raster test where that pays), "
           "queries (hardware occlusion queries with history, batching and occupancy maps; the default before two-phase), oracle (the visible parts, whole), oracle-clusters (only their clusters that own a pixel), "
           "oracle-boxes (every cluster whose box passes against the final depth: the floor of a cluster-box culler; measures --volume-bound), "
           "oracle-budgetP (oracle-clusters less what an oracle with a budget of P% of the pixels leaves out); "
           "ablations of full: full-hzb (the pyramid alone), full-tri (every part whose volume passes then tested on its own triangles, and draws marked), full-nohist (every part drawn early tested again each frame), full-nocost (every volume the pyramid lets through tested), full-noclusters (parts drawn whole, no cluster tests), full-noclusterhist (early parts drawn with all their clusters, not only those that showed last frame), full-markclusterhist (which clusters showed judged by their fragments' marks when drawn, not by their boxes against the final depth), full-noworker (the deferred clusters tested on the render thread as they are drawn, not ahead of them on a worker), full-ring (every volume's outline widened by a ring, boxes not grown across the view), full-noroundpyramid (the clusters of parts drawn after a raster test tested against the early pass's pyramid, not one built again before their round), full-splitwaits (full, measuring: waits for the drawing apart before each depth read and raster test, and times the pyramid tests: the Cheap tests table's own cost per test), full-nosubmit (full with its drawing handed to the GPU only where it reads something back, not every EngineOptions::submitTriangles triangles), full-testprobe (the cost model's probe, while tests are off, a frame that tests rather than a test of the frame's parts against its final depth), full-rasterrefresh (the parts drawn early tested for next frame by a batched raster test against the final depth, not against the pyramid of the final depth that cluster history's record reads), full-ownrecord (cluster history's record projects every cluster again, not taking what the frame's own cluster tests learned), full-notexel (no per-texel tests: a volume or cluster the pyramid test at its span lets through is not tested again texel by texel against its front faces' planes), full-obbpoints (a part tested with its PCA box projected as its 8 points, with no front-face planes or outline for the per-texel test), full-nolatepyramid (the parts waiting for the raster test not tested first against a pyramid of the depth after the deferred clusters are drawn); "
           "vfc-noclusters (vfc drawing parts whole), vfc-again (vfc a second time, among the other modes: the noise floor of a ratio to vfc); "
           "approximate full: budgetP (at most P percent of the frame's pixels lost, e.g. budget0.1), budgetearlyP (and early-set parts showing less than the budget handed to it), budgetrecountP (the parts that could fit drawn last, counted again against the depth of the rest); "
           "settings of queries: approximate thrN (pixel threshold), latency1 (last frame's results), "
           "skipN (history max skip N, 2 per visible), overlap (overlapping batches), smallN (small-feature pixels); "
           "backend: noflush (no glFlush after each batch); "
           "conservative: frontN (front-most N% of leaves drawn without queries); "
           "ablations: queries-nohist, queries-nobatch, queries-noocc, queries-notight, queries-nodrawq; order (waiting nodes hold back farther overlapping ones); settings of queries combine with '+' "
           "(thr16+latency1); full, queries and their settings take a volume: aabb, obb, kdop14, kdop18, kdop26, auto (full+kdop26, thr16+obb)";
}

bool queriesNodeVolumes(const ModeSpec& m) {
    return !m.oracle && (m.scheduler.mode == CullMode::Queries || m.scheduler.mode == CullMode::TwoPhase) &&
           m.scheduler.features.useTightVolumes;
}

namespace {

/// Whether one of the '+'-separated parts of a mode name is a volume ("full+kdop26").
bool namesVolume(const std::string& name) {
    std::size_t start = 0;
    while (true) {
        const std::size_t plus = name.find('+', start);
        if (parseVolumeChoice(name.substr(start, plus == std::string::npos ? std::string::npos : plus - start))) return true;
        if (plus == std::string::npos) return false;
        start = plus + 1;
    }
}

}  // namespace

Status setVolume(std::vector<ModeSpec>& modes, const std::string& volume) {
    auto v = parseVolumeChoice(volume);
    if (!v) return Error{"--volume: " + v.error().message};
    for (ModeSpec& m : modes) {
        if (!queriesNodeVolumes(m) || namesVolume(m.name)) continue;
        m.scheduler.tuning.volume = *v;
    }
    return {};
}

Expected<std::vector<ModeSpec>> withVolumes(std::vector<ModeSpec> modes, const std::string& list) {
    std::vector<VolumeChoice> volumes;
    for (const std::string& name : splitCommas(list)) {
        auto v = parseVolumeChoice(name);
        if (!v) return Error{"--volumes: " + v.error().message};
        if (std::find(volumes.begin(), volumes.end(), *v) != volumes.end())
            return Error{"--volumes: '" + name + "' given twice"};
        volumes.push_back(*v);
    }
    std::vector<ModeSpec> out;
    for (ModeSpec& m : modes) {
        if (!queriesNodeVolumes(m)) {
            out.push_back(std::move(m));
            continue;
        }
        if (namesVolume(m.name))
            return Error{"--volumes: mode '" + m.name + "' already names its volume"};
        for (VolumeChoice v : volumes) {
            ModeSpec c = m;
            c.name = m.name + "+" + toString(v);
            c.scheduler.tuning.volume = v;
            out.push_back(std::move(c));
        }
    }
    return out;
}

namespace {

/// Applies one setting of `queries` (an approximate setting or an ablation) to `m`.
bool applyQueriesSetting(const std::string& part, ModeSpec& m) {
    std::uint32_t n = 0;
    if (part == "queries") {
    } else if (part == "latency1") {
        m.scheduler.approx.useLastFrameResults = true;
    } else if (part == "noflush") {
        m.queries.flushAfterBatch = false;
    } else if (part == "overlap") {
        m.scheduler.approx.batchOverlapping = true;
    } else if (part == "queries-nohist") {
        m.scheduler.features.useHistory = false;
    } else if (part == "queries-nobatch") {
        m.scheduler.features.useBatching = false;
    } else if (part == "queries-noocc") {
        m.scheduler.features.useOccupancyAccept = false;
    } else if (part == "queries-notight") {
        m.scheduler.features.useTightVolumes = false;
    } else if (part == "queries-nodrawq") {
        m.scheduler.features.useDrawQueries = false;
    } else if (part == "order") {
        m.scheduler.features.useWaitOrder = true;
    } else if (numberAfter(part, "thr", n)) {
        m.queries.visiblePixelThreshold = n;
    } else if (numberAfter(part, "skip", n)) {
        m.scheduler.tuning.history.maxSkipFrames = n;
        m.scheduler.tuning.history.skipFramesPerVisible = 2;
    } else if (numberAfter(part, "small", n)) {
        m.scheduler.approx.smallFeaturePixels = n;
    } else if (numberAfter(part, "front", n)) {
        m.scheduler.tuning.frontPercent = static_cast<float>(n);
    } else {
        return false;
    }
    return true;
}

}  // namespace

namespace {
// The families' names: one per approximation, shared by named modes and sweeps.
constexpr const char* kErrorBudgetFamily = "error budget";
constexpr const char* kThresholdFamily = "sample threshold";
constexpr const char* kSmallFeatureFamily = "small features";
constexpr const char* kLatencyFamily = "latency";
}  // namespace

std::string approximationFamily(const ModeSpec& m) {
    if (m.oracle) return {};
    const SchedulerApproximations& a = m.scheduler.approx;
    std::string family;
    auto add = [&](const char* what) { family += (family.empty() ? "" : " + ") + std::string(what); };
    if (a.errorBudgetPercent > 0) {
        add(kErrorBudgetFamily);
        family += a.budgetEarlySet ? ", early set" : a.budgetRecount ? ", recount" : "";
    }
    if (m.queries.visiblePixelThreshold > 0) add(kThresholdFamily);
    if (a.smallFeaturePixels > 0) add(kSmallFeatureFamily);
    if (a.useLastFrameResults) add(kLatencyFamily);
    return family;
}

Expected<ModeSpec> modeFromName(const std::string& name) {
    ModeSpec m = queriesMode(name);
    if (name == "vfc" || name == "vfc-noclusters" || name == "vfc-again") {
        m.scheduler.mode = CullMode::Vfc;
        m.scheduler.features.useClusters = name != "vfc-noclusters";
    } else if (name == "simple") {
        m.scheduler.mode = CullMode::Simple;
    } else if (name == "oracle" || name == "oracle-clusters") {
        m.oracle = true;
        m.oracleClusters = name == "oracle-clusters";
    } else if (name == "oracle-boxes") {
        m.oracle = m.oracleBoxes = true;
    } else if (double budget = 0.0; percentAfter(name, "oracle-budget", budget)) {
        if (!(budget > 0.0)) return Error{"--modes: '" + name + "': the budget must be above 0"};
        m.oracle = m.oracleClusters = true;
        m.oracleBudgetPercent = budget;
    } else {
        // `full` or one of its ablations, or settings of `queries`, combined with '+'
        // (thr16+latency1); at most one part is a volume.
        std::size_t start = 0;
        bool volume = false, twoPhase = false, querySetting = false;
        while (true) {
            const std::size_t plus = name.find('+', start);
            const std::string part = name.substr(start, plus == std::string::npos ? std::string::npos : plus - start);
            if (auto v = parseVolumeChoice(part)) {
                if (volume) return Error{"--modes: '" + name + "' names two volumes"};
                volume = true;
                m.scheduler.tuning.volume = *v;
            } else if (!twoPhase && !querySetting && applyTwoPhaseName(part, m)) {
                twoPhase = true;
            } else if (!twoPhase && applyQueriesSetting(part, m)) {
                querySetting = true;
            } else if (twoPhase || (querySetting && applyTwoPhaseName(part, m))) {
                return Error{"--modes: '" + name + "': '" + part + "' does not combine with " + (twoPhase ? "full" : "settings of queries") +
                             " (full and its ablations take only a volume)"};
            } else {
                return Error{"--modes: unknown mode '" + part + "' in '" + name + "' (known: " + modeNamesHelp() + ")"};
            }
            if (plus == std::string::npos) break;
            start = plus + 1;
        }
        if (volume && !queriesNodeVolumes(m))
            return Error{"--modes: '" + name + "': queries-notight queries world boxes and takes no volume"};
    }
    if (Status s = validateSchedulerParams(m.scheduler); !s) return Error{"--modes: " + name + ": " + s.message()};
    m.family = approximationFamily(m);
    return m;
}

Expected<std::vector<ModeSpec>> modesFromList(const std::string& list) {
    std::vector<ModeSpec> out;
    for (const std::string& name : splitCommas(list)) {
        if (name.empty()) return Error{"--modes: empty mode name in '" + list + "'"};
        for (const ModeSpec& m : out)
            if (m.name == name) return Error{"--modes: '" + name + "' given twice"};
        auto m = modeFromName(name);
        if (!m) return m.error();
        out.push_back(m.take());
    }
    return out;
}

std::string sweepParamsHelp() {
    return "pixel-threshold, max-skip, skip-per-visible, small-feature, max-in-flight, tile-size, auto-saving (percent), "
           "latency (0 or 1 frames); error-budget (full; percent of the frame's pixels, decimals allowed); pyramid-span (full; "
           "texels a side of the late pass's pyramid tests, 2 to 64); cluster-span (full; the same for cluster tests); record-span (full; the same for cluster history's frame-end record); texel-tests (full; texels the late pass's per-texel test reads at most, 0 for off); cluster-texel-tests (full; the same for cluster tests); candidate-rounds (full; rounds of the late pass's raster tests, 1 to 16); test-ns (full; the cost model's nanoseconds per batched volume "
           "test, TestCosts::testNsPerVolume); batch-ns (full; the cost model's nanoseconds per round of raster tests before its first volume, TestCosts::testNsPerBatch, 0 for every round); pyramid-ns (full; the cost model's nanoseconds per pyramid built again before a round, "
           "TestCosts::pyramidNs); record-worker (full; clusters from which cluster history's frame-end record shares its tests with a second thread, SchedulerTuning::recordWorkerClusters); submit-tris (full; triangles drawn between two glFlush calls, EngineOptions::submitTriangles, 0 for none)";
}

namespace {
// full's sweep parameters that count texels (int tuning fields): the swept value is clamped
// into an int here and checked by validateSchedulerParams.
constexpr std::pair<const char*, int SchedulerTuning::*> kTwoPhaseTexelParams[] = {
    {"pyramid-span", &SchedulerTuning::pyramidSpan},          {"cluster-span", &SchedulerTuning::clusterPyramidSpan},
    {"record-span", &SchedulerTuning::recordPyramidSpan},     {"texel-tests", &SchedulerTuning::texelTestTexels},
    {"cluster-texel-tests", &SchedulerTuning::clusterTexelTests}};
}  // namespace

Expected<std::vector<ModeSpec>> sweepModes(const std::string& spec) {
    const std::size_t eq = spec.find('=');
    if (eq == std::string::npos || eq == 0 || eq + 1 == spec.size())
        return Error{"--param: expected NAME=v1,v2,... (NAME one of " + sweepParamsHelp() + "), got '" + spec + "'"};
    const std::string param = spec.substr(0, eq);
    std::vector<ModeSpec> out;
    for (const std::string& text : splitCommas(spec.substr(eq + 1))) {
        std::uint32_t v = 0;
        double percent = 0.0;
        ModeSpec m = queriesMode(param + "=" + text);
        if (param == "error-budget") {
            if (!parsePercent(text, percent))
                return Error{"--param error-budget: '" + text + "' is not a percentage in (0, 100]"};
            m.scheduler.mode = CullMode::TwoPhase;
            m.scheduler.approx.errorBudgetPercent = percent;
        } else if (!parseU32(text, v)) {
            return Error{"--param " + param + ": '" + text + "' is not a non-negative integer"};
        } else if (param == "latency") {
            if (v > 1) return Error{"--param latency: '" + text + "' is not 0 or 1 (frames of latency)"};
            m.scheduler.approx.useLastFrameResults = v == 1;
        } else if (param == "pixel-threshold") {
            m.queries.visiblePixelThreshold = v;
        } else if (param == "max-skip") {
            m.scheduler.tuning.history.maxSkipFrames = v;
        } else if (param == "skip-per-visible") {
            m.scheduler.tuning.history.skipFramesPerVisible = v;
        } else if (param == "small-feature") {
            m.scheduler.approx.smallFeaturePixels = v;
        } else if (param == "max-in-flight") {
            m.scheduler.tuning.maxQueriesInFlight = v;
        } else if (param == "tile-size") {
            m.scheduler.tuning.occupancyTileSize = static_cast<int>(std::min<std::uint32_t>(v, 1u << 20));
        } else if (const auto texels = std::find_if(std::begin(kTwoPhaseTexelParams), std::end(kTwoPhaseTexelParams),
                                                    [&](const auto& t) { return param == t.first; });
                   texels != std::end(kTwoPhaseTexelParams)) {
            m.scheduler.mode = CullMode::TwoPhase;
            m.scheduler.tuning.*texels->second = static_cast<int>(std::min<std::uint32_t>(v, 1u << 20));
        } else if (param == "candidate-rounds") {
            m.scheduler.mode = CullMode::TwoPhase;
            m.scheduler.tuning.candidateRounds = v;
        } else if (param == "pyramid-ns") {
            m.scheduler.mode = CullMode::TwoPhase;
            m.scheduler.tuning.costs.pyramidNs = double(v);
        } else if (param == "record-worker") {
            m.scheduler.mode = CullMode::TwoPhase;
            m.scheduler.tuning.recordWorkerClusters = v;
        } else if (param == "submit-tris") {
            m.scheduler.mode = CullMode::TwoPhase;
            m.submitTriangles = v;
        } else if (param == "batch-ns") {
            m.scheduler.mode = CullMode::TwoPhase;
            m.scheduler.tuning.costs.testNsPerBatch = double(v);
        } else if (param == "test-ns") {
            m.scheduler.mode = CullMode::TwoPhase;
            m.scheduler.tuning.costs.testNsPerVolume = double(v);
        } else if (param == "auto-saving") {
            m.scheduler.tuning.volume = VolumeChoice::Auto;
            m.scheduler.tuning.autoVolumeSaving = static_cast<float>(v) / 100.0f;
        } else {
            return Error{"--param: unknown parameter '" + param + "' (known: " + sweepParamsHelp() + ")"};
        }
        if (Status s = validateSchedulerParams(m.scheduler); !s) return Error{"--param " + m.name + ": " + s.message()};
        for (const ModeSpec& o : out)
            if (o.name == m.name) return Error{"--param: value " + text + " given twice"};
        // Every value of a parameter is one family (its 0 the curve's conservative end), named
        // as approximationFamily names the approximation the parameter sets.
        m.family = param == "error-budget"      ? kErrorBudgetFamily
                   : param == "pixel-threshold" ? kThresholdFamily
                   : param == "small-feature"   ? kSmallFeatureFamily
                   : param == "latency"         ? kLatencyFamily
                                                : param;
        out.push_back(std::move(m));
    }
    return out;
}

Expected<std::unique_ptr<BenchRunner>> BenchRunner::create(Engine& engine, DemoScene& scene, std::vector<ModeSpec> modes) {
    std::unique_ptr<BenchRunner> r(new BenchRunner(engine, scene));
    // vfc is mode 0: its image is the reference the others are compared to.
    const auto vfc = std::find_if(modes.begin(), modes.end(), [](const ModeSpec& m) { return m.name == "vfc"; });
    if (vfc == modes.end()) {
        auto m = modeFromName("vfc");
        modes.insert(modes.begin(), m.take());
    } else {
        std::rotate(modes.begin(), vfc, vfc + 1);
    }
    for (const ModeSpec& m : modes) {
        if (Status s = validateSchedulerParams(m.scheduler); !s) return Error{m.name + ": " + s.message()};
        r->schedulers_.push_back(m.oracle ? nullptr : std::make_unique<QueryScheduler>(m.scheduler));
    }
    auto gt = GroundTruth::create(engine.context());
    if (!gt) return gt.error();
    r->groundTruth_ = gt.take();
    // Visible clusters only where a mode needs them: the ID pass costs twice as much then.
    r->groundTruth_->setClusterIds(std::any_of(modes.begin(), modes.end(), [](const ModeSpec& m) { return m.oracleClusters; }));
    r->groundTruth_->setMeshSubstitute(scene.truthGeometry());
    r->modesNeedBound_ = std::any_of(modes.begin(), modes.end(), [](const ModeSpec& m) { return m.oracleBoxes; });
    r->setMeasureVolumeBound(false, r->boundBudgetPercent_);
    BenchResult& res = r->result_;
    res.modes = std::move(modes);
    res.scene = scene.name();
    res.description = scene.description();
    res.renderer = engine.context().rendererName();
    res.width = engine.context().size().x;
    res.height = engine.context().size().y;
    r->images_.resize(res.modes.size());
    r->missing_.resize(res.modes.size());
    return r;
}

namespace {
/// Appends `r` to `out`, merged into the last range if that is the same part's and ends
/// where `r` starts: the oracles draw each run of adjacent clusters as one range.
void appendRange(std::vector<PartRange>& out, const PartRange& r) {
    PartRange* prev = out.empty() ? nullptr : &out.back();
    if (prev && prev->part == r.part && prev->firstIndex + prev->indexCount == r.firstIndex)
        prev->indexCount += r.indexCount;
    else
        out.push_back(r);
}
}  // namespace

void BenchRunner::oracleRanges(std::span<const std::uint8_t> droppedClusters, std::span<const std::uint8_t> droppedParts,
                               std::vector<PartRange>& out) const {
    out.clear();
    if (truth_.clusterFirst.empty()) return;
    for (const NodeRef& ref : oracleParts_) {
        const LocalBsp& model = engine_.objects().model(engine_.objects().modelOf(ref.object));
        const auto at = std::lower_bound(truth_.parts.begin(), truth_.parts.end(), ref);
        const auto i = static_cast<std::size_t>(at - truth_.parts.begin());
        const std::size_t first = truth_.clusterFirst[i], last = truth_.clusterFirst[i + 1];
        if (first == last) {  // no clusters: the whole part
            if (!droppedParts.empty() && droppedParts[i]) continue;
            const LocalBspNode& n = model.nodes[ref.node];
            out.push_back({ref, n.firstIndex, n.indexCount});
            continue;
        }
        for (std::size_t c = first; c < last; ++c) {
            if (!droppedClusters.empty() && droppedClusters[c]) continue;
            const LeafCluster& cl = model.clusters.clusters[truth_.clusters[c]];
            appendRange(out, {ref, cl.firstIndex, cl.indexCount});
        }
    }
}

Status BenchRunner::runFrame(std::uint64_t frame) {
    const glm::ivec2 size = engine_.context().size();
    const float aspect = static_cast<float>(size.x) / static_cast<float>(size.y);
    if (Status s = scene_.update(engine_, frame); !s) return s;
    if (Status s = engine_.setCamera(scene_.camera(frame, aspect)); !s) return s;
    scene_.beginFrame(engine_.camera());

    // Relink once for all modes, so no mode pays for the others' motion.
    FrameTruth ft;
    ft.updateMs = engine_.updateSceneTree().updateMs;
    truth_ = groundTruth_->compute(engine_, engine_.camera());
    ft.groundTruthMs = groundTruth_->lastMs();
    ft.visibleParts = static_cast<std::uint32_t>(truth_.parts.size());
    ft.frustumParts = truth_.candidates;
    ft.coveredPixels = truth_.coveredPixels;
    ft.artefactPixels = truth_.artefactPixels;
    for (const NodeRef& k : truth_.parts) ft.visibleTriangles += engine_.objects().model(engine_.objects().modelOf(k.object)).nodes[k.node].indexCount / 3;
    ft.visibleClusterTriangles = truth_.visibleClusterTriangles;

    // The oracle draws the visible parts front-to-back like the other modes, so it gets
    // the same early-depth rejection and is a fair lower bound.
    const TwoLevelTree tree(engine_.sceneTree(), engine_.objects());
    const glm::vec3 eye = engine_.camera().position;
    std::vector<std::pair<float, NodeRef>> byDistance;
    byDistance.reserve(truth_.parts.size());
    for (const NodeRef& k : truth_.parts) {
        const NodeRef ref{k.object, k.node};
        const glm::vec3 d = tree.worldBox(ref).center() - eye;
        byDistance.push_back({glm::dot(d, d), ref});
    }
    std::sort(byDistance.begin(), byDistance.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
    oracleParts_.clear();
    for (const auto& p : byDistance) oracleParts_.push_back(p.second);
    // Only where a mode draws them (GroundTruth::setClusterIds): each part's visible clusters.
    oracleRanges({}, {}, oracleClusterRanges_);
    oracleBudgetRanges_.resize(result_.modes.size());
    oracleBudgetPixels_.assign(result_.modes.size(), 0);
    const bool budgetOracle = std::any_of(result_.modes.begin(), result_.modes.end(), [](const ModeSpec& m) { return m.oracleBudgetPercent > 0; });
    if (budgetOracle && !truth_.clusterFirst.empty()) {
        // The budget oracle's items, the same for every budget: the visible clusters, then
        // the visible parts without clusters, each with its triangles and own pixels.
        itemTriangles_.clear();
        itemPixels_.clear();
        itemWholeParts_.clear();
        for (std::size_t i = 0; i < truth_.parts.size(); ++i) {
            const LocalBsp& model = engine_.objects().model(engine_.objects().modelOf(truth_.parts[i].object));
            for (std::size_t c = truth_.clusterFirst[i]; c < truth_.clusterFirst[i + 1]; ++c) {
                itemTriangles_.push_back(model.clusters.clusters[truth_.clusters[c]].indexCount / 3);
                itemPixels_.push_back(truth_.clusterPixels[c]);
            }
        }
        for (std::size_t i = 0; i < truth_.parts.size(); ++i) {
            if (truth_.clusterFirst[i] != truth_.clusterFirst[i + 1]) continue;
            itemWholeParts_.push_back(static_cast<std::uint32_t>(i));
            itemTriangles_.push_back(engine_.objects().model(engine_.objects().modelOf(truth_.parts[i].object)).nodes[truth_.parts[i].node].indexCount / 3);
            itemPixels_.push_back(truth_.pixels[i]);
        }
        for (std::size_t m = 0; m < result_.modes.size(); ++m) {
            const double percent = result_.modes[m].oracleBudgetPercent;
            if (percent <= 0.0) continue;
            BudgetDrops drops = chooseBudgetDrops(itemTriangles_, itemPixels_, errorBudgetPixels(percent, size.x, size.y));
            std::vector<std::uint8_t> droppedParts(truth_.parts.size(), 0);
            for (std::size_t k = 0; k < itemWholeParts_.size(); ++k)
                droppedParts[itemWholeParts_[k]] = drops.dropped[truth_.clusters.size() + k];
            drops.dropped.resize(truth_.clusters.size());
            oracleRanges(drops.dropped, droppedParts, oracleBudgetRanges_[m]);
            oracleBudgetPixels_[m] = drops.pixels;
        }
    }

    if (measureBound_) {
        // The bounds test against the frame's final depth, drawn here, untimed, before the
        // modes (whose order rotates, so no mode's own depth can serve): the oracle's parts
        // are every part that owns a pixel, so their depth is what drawing all would leave.
        engine_.setQueryParams(GlQueryParams{});  // conservative: the last mode's may have a threshold
        engine_.context().clearFramebuffer(Renderer::kClearColour);
        scene_.setReferencePass(true);
        auto drawn = engine_.renderParts(oracleParts_);
        scene_.setReferencePass(false);
        if (!drawn) return Error{"frame " + std::to_string(frame) + ", the bound's depth: " + drawn.error().message};
        ft.boundMeasured = true;
        ft.boundAabb = volumeBound(VolumeChoice::Aabb);
        ft.boundAuto = volumeBound(VolumeChoice::Auto);
        ft.boundClusters = clusterBound();
    }

    std::vector<ModeFrame> row(result_.modes.size());
    // Every mode takes every place in the order in turn, vfc too: the order rotates every
    // frame. On llvmpipe the first mode of a frame ran up to 8% slower than the same mode
    // later in it (`vfc-again`), and the mode right after vfc slower than the others
    // (docs/BENCHMARKS.md), so no mode may always take one place. A scene whose reference
    // pass loads what later passes find keeps vfc first.
    const std::size_t n = result_.modes.size(), turn = result_.frames.size() + orderOffset_;
    const bool vfcFirst = scene_.referencePassLoads();
    drawn_.resize(n);
    for (std::size_t k = 0; k < n; ++k) {
        const std::size_t m = !vfcFirst ? (k + turn) % n : k == 0 ? 0 : 1 + (k - 1 + turn) % (n - 1);
        const ModeSpec& spec = result_.modes[m];
        engine_.setQueryParams(spec.queries);
        engine_.setSubmitTriangles(spec.submitTriangles);
        if (schedulers_[m]) schedulers_[m]->setTrace(&trace_);
        engine_.context().clearFramebuffer(Renderer::kClearColour);
        // The reference image is complete even where the scene may skip work (streamed
        // leaves not yet read), so what a mode skips counts as its error.
        scene_.setReferencePass(m == 0);
        auto rendered = spec.oracleBoxes              ? engine_.renderPartRanges(boundRanges_)
                        : spec.oracleBudgetPercent > 0 ? engine_.renderPartRanges(oracleBudgetRanges_[m])
                        : spec.oracleClusters         ? engine_.renderPartRanges(oracleClusterRanges_)
                        : spec.oracle       ? engine_.renderParts(oracleParts_)
                                            : engine_.renderFrame(*schedulers_[m]);
        scene_.setReferencePass(false);
        if (schedulers_[m]) schedulers_[m]->setTrace(nullptr);
        if (!rendered) {
            return Error{"frame " + std::to_string(frame) + ", mode " + spec.name + ": " + rendered.error().message};
        }
        row[m].stats = *rendered;
        if (spec.oracleBudgetPercent > 0) row[m].stats.claimedErrorPixels = oracleBudgetPixels_[m];
        drawn_[m] = drawnLeaves(engine_.objects(), engine_.visibleParts());
        row[m].parts = compareParts(truth_, drawn_[m]);
        images_[m] = engine_.renderer().readPixels();
        countPopIn(m, drawn_[m], row[m]);
        if (!spec.oracle) row[m].falsePositiveCauses = falsePositiveCauses();
    }
    // Every image against vfc's, which may have been drawn after it.
    for (std::size_t m = 0; m < n; ++m) {
        auto diff = compareImages(images_[m], images_[0], &diffMask_);
        if (!diff) return Error{diff.error().message};
        row[m].image = *diff;
        splitDifferingPixels(drawn_[m], row[m]);
    }
    auto streamed = scene_.endFrame();
    if (!streamed) return streamed.error();
    if (*streamed) result_.streaming.add(frame, **streamed, row[0].stats.frameMs);
    result_.truth.push_back(ft);
    result_.frames.push_back(std::move(row));
    return {};
}

void BenchRunner::splitDifferingPixels(const std::vector<NodeRef>& drawn, ModeFrame& out) const {
    // The ground truth's id image and the diff mask are both top-down, width x height.
    const std::vector<std::uint32_t>& ids = groundTruth_->idImage();
    const std::vector<NodeRef>& parts = groundTruth_->lastParts();
    if (ids.size() != diffMask_.size()) return;  // sizes disagree: nothing to split by
    for (std::size_t i = 0; i < diffMask_.size(); ++i) {
        if (!diffMask_[i]) continue;
        const std::uint32_t id = ids[i];
        const bool lost = id != 0 && id <= parts.size() && !std::binary_search(drawn.begin(), drawn.end(), parts[id - 1]);
        ++(lost ? out.lostPixels : out.tiedPixels);
    }
}

void BenchRunner::countPopIn(std::size_t mode, const std::vector<NodeRef>& drawn, ModeFrame& out) {
    std::vector<NodeRef>& missing = missing_[mode];
    for (const NodeRef& p : missing)
        if (std::binary_search(drawn.begin(), drawn.end(), p)) ++out.popIn;
    missing.clear();
    std::set_difference(truth_.parts.begin(), truth_.parts.end(), drawn.begin(), drawn.end(), std::back_inserter(missing));
}

FalsePositiveCauses BenchRunner::falsePositiveCauses() const {
    // Every leaf is decided once per frame, so each drawn leaf has one visible state.
    FalsePositiveCauses c;
    const TwoLevelTree tree(engine_.sceneTree(), engine_.objects());
    for (const NodeTrace& t : trace_) {
        if (t.ref.isSceneNode() || !tree.isDrawable(t.ref) || truth_.contains(NodeRef{t.ref.object, t.ref.node})) continue;
        switch (t.state) {
            case NodeState::FrustumCulled:
            case NodeState::Occluded:
            case NodeState::SmallFeature:
            case NodeState::ClusterCulled:
            case NodeState::BudgetCulled: break;
            case NodeState::VisibleQueried: ++c.queried; break;
            case NodeState::VisibleHistory: ++c.history; break;
            case NodeState::VisibleOccupancy: ++c.occupancy; break;
            case NodeState::VisibleNear:
            case NodeState::VisibleFront:
            case NodeState::VisibleVfc:
            case NodeState::VisibleCheaper:
            case NodeState::VisibleOccluder: ++c.other; break;
        }
    }
    return c;
}

VolumeBound BenchRunner::volumeBound(VolumeChoice volume) {
    const SceneObjects& objs = engine_.objects();
    const Camera& cam = engine_.camera();
    const TwoLevelTree tree(engine_.sceneTree(), objs);
    auto nearPlaneReached = [&](NodeRef r) {
        // Any corner of its world box closer along the view direction than the near plane
        // (with 0.1% to spare: the scheduler's own test is tighter, this one only has to be safe).
        const Aabb box = tree.worldBox(r);
        const glm::vec3 f = cam.forward();
        for (int c = 0; c < 8; ++c) {
            const glm::vec3 p((c & 1) ? box.max.x : box.min.x, (c & 2) ? box.max.y : box.min.y, (c & 4) ? box.max.z : box.min.z);
            if (glm::dot(p - cam.position, f) < cam.nearPlane * 1.001f) return true;
        }
        return false;
    };
    const std::vector<NodeRef>& parts = groundTruth_->lastParts();
    QueryBackend& backend = engine_.queryBackend();
    backend.beginFrame(FrameView::of(engine_.camera(), result_.width, result_.height));
    VolumeBound b;
    std::vector<QueryId> ids;
    constexpr std::size_t kBatch = 512;  // bounds the query objects in flight
    for (std::size_t i = 0; i < parts.size(); i += kBatch) {
        const std::size_t n = std::min(kBatch, parts.size() - i);
        ids.clear();
        backend.beginBatch();
        for (std::size_t j = 0; j < n; ++j)
            ids.push_back(backend.issue(objectNodeVolume(objs, parts[i + j], volume, SchedulerParams{}.tuning.autoVolumeSaving)));
        backend.endBatch();
        for (std::size_t j = 0; j < n; ++j) {
            // Unanswered within the bound counts visible, as in the scheduler; so does a
            // part reaching the near plane, whose query could be clipped away.
            const NodeRef r = parts[i + j];
            if (backend.wait(ids[j], 60000.0) != QueryResult::Occluded || nearPlaneReached(r)) {
                ++b.parts;
                b.triangles += objs.model(objs.modelOf(r.object)).nodes[r.node].indexCount / 3;
            }
            backend.release(ids[j]);
        }
    }
    return b;
}

void BenchRunner::setMeasureVolumeBound(bool on, double budgetPercent) {
    on = on || modesNeedBound_;
    measureBound_ = on;
    boundBudgetPercent_ = budgetPercent;
    if (on) groundTruth_->setClusterIds(true);  // which passing clusters own no pixel
}

ClusterBound BenchRunner::clusterBound() {
    const SceneObjects& objs = engine_.objects();
    const Camera& cam = engine_.camera();
    const TwoLevelTree tree(engine_.sceneTree(), objs);
    QueryBackend& backend = engine_.queryBackend();
    const FrameView view = FrameView::of(cam, result_.width, result_.height);
    backend.beginFrame(view);
    const std::vector<NodeRef>& parts = groundTruth_->lastParts();

    // Each part's own volumes (its box, PCA box and 26-DOP: a culler may test any of them,
    // so the part shows only if all pass, with the fewest samples of the three), and the
    // boxes of its clusters that do not face away and are not outside the frustum (a box
    // behind the eye would reach the near plane and pass).
    struct Box {
        std::uint32_t part = 0;  // index in `parts`
        std::uint32_t cluster = kInvalidIndex;  // into its model's clusters; kInvalidIndex: a part volume
    };
    std::vector<Box> boxes;
    std::vector<std::uint32_t> boxSamples;  // per box: 0 if it did not pass, else its samples (or kUnknownSamples)
    std::vector<QueryVolume> volumes;       // the batch being built: boxes [tested, tested + size)
    std::vector<QueryResult> answers;
    std::vector<std::uint32_t> samples;
    auto test = [&] {
        if (volumes.empty()) return;
        answers.assign(volumes.size(), QueryResult::Visible);
        samples.assign(volumes.size(), kUnknownSamples);
        const BatchId id = backend.testVolumes(volumes, true);
        if (id != kNoBatch) backend.collectVolumes(id, answers, 60000.0, samples);  // else: all pass, unknown
        for (std::size_t i = 0; i < volumes.size(); ++i)
            boxSamples.push_back(answers[i] == QueryResult::Occluded ? 0u : samples[i]);
        volumes.clear();
    };
    // A part drawn as its clusters: its model has them, and it has some (a hand-built
    // tree's leaves may have none).
    auto clustered = [&](const LocalBsp& model, NodeRef r) {
        return model.clusters.builtFor(model.nodes.size()) &&
               model.clusters.nodeFirst[r.node] != model.clusters.nodeFirst[r.node + model.nodes[r.node].subtreeSize];
    };
    constexpr std::size_t kBatch = 4096;  // bounds the volumes copied per draw
    const float autoSaving = SchedulerParams{}.tuning.autoVolumeSaving;
    for (std::uint32_t p = 0; p < parts.size(); ++p) {
        const NodeRef r = parts[p];
        const LocalBsp& model = objs.model(objs.modelOf(r.object));
        const LocalBspNode& node = model.nodes[r.node];
        for (const VolumeChoice v : {VolumeChoice::Aabb, VolumeChoice::Obb, VolumeChoice::Kdop26}) {
            volumes.push_back(objectNodeVolume(objs, r, v, autoSaving));
            boxes.push_back({p, kInvalidIndex});
        }
        if (clustered(model, r)) {
            const glm::mat4& toWorld = objs.matrix(r.object);
            const bool cones = model.faces == FaceMode::CullBack;
            const ObjectSpaceEye eye(cam, toWorld);
            for (std::uint32_t c = model.clusters.nodeFirst[r.node]; c < model.clusters.nodeFirst[r.node + node.subtreeSize]; ++c) {
                const LeafCluster& cluster = model.clusters.clusters[c];
                if (cones && eye.backFacing(cluster)) continue;
                if (view.frustum.outside(transformAabb(toWorld, cluster.box))) continue;
                volumes.push_back(QueryVolume::fromTransformedBox(toWorld, cluster.box));
                boxes.push_back({p, c});
            }
        }
        if (volumes.size() >= kBatch) test();
    }
    test();
    assert(boxSamples.size() == boxes.size());

    // A part's volumes come first, then its clusters, so one pass in order decides both.
    ClusterBound b;
    std::vector<std::pair<float, PartRange>> passing;  // (part's squared distance, range) of every passing item
    std::vector<std::uint32_t> itemTriangles, itemSamples;  // the budget's items with known samples
    for (std::size_t i = 0; i < boxes.size();) {
        const std::uint32_t p = boxes[i].part;
        const NodeRef r = parts[p];
        const LocalBsp& model = objs.model(objs.modelOf(r.object));
        const LocalBspNode& node = model.nodes[r.node];
        std::uint32_t partSamples = kUnknownSamples;
        for (; i < boxes.size() && boxes[i].part == p && boxes[i].cluster == kInvalidIndex; ++i)
            partSamples = std::min(partSamples, boxSamples[i]);
        const std::size_t clustersBegin = i;
        while (i < boxes.size() && boxes[i].part == p) ++i;
        if (partSamples == 0) continue;  // one of its volumes is hidden: the part is
        const glm::vec3 d = tree.worldBox(r).center() - cam.position;
        const float distance = glm::dot(d, d);
        // The part's clusters that own a pixel (indices into model.clusters), if it is visible.
        const auto at = std::lower_bound(truth_.parts.begin(), truth_.parts.end(), r);
        const bool visible = at != truth_.parts.end() && *at == r;
        std::span<const std::uint32_t> shown;
        if (visible && !truth_.clusterFirst.empty()) {
            const std::size_t k = static_cast<std::size_t>(at - truth_.parts.begin());
            shown = std::span(truth_.clusters).subspan(truth_.clusterFirst[k], truth_.clusterFirst[k + 1] - truth_.clusterFirst[k]);
        }
        auto pass = [&](std::uint32_t firstIndex, std::uint32_t indexCount, std::uint32_t boxSamplesOf, bool hidden) {
            const std::uint32_t tris = indexCount / 3;
            passing.push_back({distance, PartRange{r, firstIndex, indexCount}});
            ++b.clusters;
            b.triangles += tris;
            if (boxSamplesOf == kUnknownSamples) ++b.unknownSamples;
            else itemTriangles.push_back(tris), itemSamples.push_back(boxSamplesOf);
            if (!hidden) return;
            ++b.hiddenClusters;
            b.hiddenTriangles += tris;
            if (boxSamplesOf != kUnknownSamples) b.hiddenSamples += boxSamplesOf;
        };
        std::uint64_t partTriangles = 0;  // of its passing items
        if (!clustered(model, r)) {
            pass(node.firstIndex, node.indexCount, partSamples, !visible);
            continue;  // the part is the item
        }
        for (std::size_t j = clustersBegin; j < i; ++j) {
            if (boxSamples[j] == 0) continue;
            const LeafCluster& cluster = model.clusters.clusters[boxes[j].cluster];
            pass(cluster.firstIndex, cluster.indexCount, boxSamples[j], !std::binary_search(shown.begin(), shown.end(), boxes[j].cluster));
            partTriangles += cluster.indexCount / 3;
        }
        // Left out whole, for its volumes' samples: possibly fewer than its clusters' sum.
        if (partTriangles > 0 && partSamples != kUnknownSamples)
            itemTriangles.push_back(static_cast<std::uint32_t>(partTriangles)), itemSamples.push_back(partSamples);
    }
    // Front to back by part, as the oracle draws; a part's passing clusters in index order,
    // adjacent ones merged into one range.
    std::stable_sort(passing.begin(), passing.end(), [](const auto& x, const auto& y) { return x.first < y.first; });
    boundRanges_.clear();
    for (const auto& [dist, range] : passing) appendRange(boundRanges_, range);
    // Any culler's drops are disjoint items of this list (whole parts, or clusters), so the
    // fractional knapsack over all of them bounds what a budget can leave out.
    b.budgetPixels = errorBudgetPixels(boundBudgetPercent_, result_.width, result_.height);
    b.budgetTriangleBound = chooseBudgetDrops(itemTriangles, itemSamples, b.budgetPixels).triangleBound;
    return b;
}

void BenchRunner::keepFastest(const BenchResult& other) {
    assert(other.frames.size() == result_.frames.size() && other.modes.size() == result_.modes.size());
    for (std::size_t f = 0; f < result_.frames.size(); ++f)
        for (std::size_t m = 0; m < result_.modes.size(); ++m) {
            FrameStats& mine = result_.frames[f][m].stats;
            const FrameStats& theirs = other.frames[f][m].stats;
            mine.frameMs = std::min(mine.frameMs, theirs.frameMs);
            result_.passFramesApart += mine.trianglesDrawn != theirs.trianglesDrawn;
        }
    ++result_.passes;
}

void BenchRunner::measureLeafVolumes() {
    result_.leafTotals.assign(result_.modes.size(), {});
    for (std::size_t m = 0; m < result_.modes.size(); ++m) {
        const ModeSpec& spec = result_.modes[m];
        if (queriesNodeVolumes(spec))
            result_.leafTotals[m] = leafVolumeTotals(engine_.objects(), spec.scheduler.tuning.volume, spec.scheduler.tuning.autoVolumeSaving);
    }
}

}  // namespace dyncull::cli

namespace dyncull::cli {

namespace {

/// One pass's scene, context, engine and runner (destroyed in reverse order).
struct Pass {
    std::unique_ptr<DemoScene> scene;
    std::unique_ptr<GlContext> context;
    std::unique_ptr<Engine> engine;
    std::unique_ptr<BenchRunner> runner;
};

Expected<Pass> startPass(const MeasureOptions& o, std::vector<ModeSpec> modes, bool print) {
    Pass p;
    auto made = makeScene(o.scene, o.sceneOptions);
    if (!made) return Error{made.error().message};
    p.scene = made.take();
    ContextOptions co;
    co.width = o.size.x;
    co.height = o.size.y;
    auto context = GlContext::create(co);
    if (!context) return Error{context.error().message};
    p.context = context.take();
    EngineOptions eo;
    eo.finishEachFrame = true;  // frame times include the GPU's work
    auto engine = Engine::create(*p.context, eo);
    if (!engine) return Error{engine.error().message};
    p.engine = engine.take();
    if (Status s = p.scene->populate(*p.engine); !s) return Error{s.message()};
    if (print) {
        std::printf("%s\n", p.scene->description().c_str());
        std::printf("context: %s, %s; set-up %.0f ms\n", p.context->platformName().c_str(), p.context->rendererName().c_str(),
                    p.scene->setupMs());
    }
    auto runner = BenchRunner::create(*p.engine, *p.scene, std::move(modes));
    if (!runner) return Error{runner.error().message};
    p.runner = runner.take();
    p.runner->setMeasureVolumeBound(o.volumeBound, o.boundBudgetPercent);
    if (print) {
        std::string names;
        for (const ModeSpec& m : p.runner->result().modes) names += (names.empty() ? "" : ",") + m.name;
        std::printf("modes (interleaved per frame, in an order rotated every frame%s): %s\n",
                    p.scene->referencePassLoads() ? ", vfc always first" : "", names.c_str());
        if (o.passes > 1) std::printf("passes: %u, each mode's least time per frame kept\n", o.passes);
        std::fflush(stdout);
    }
    return p;
}

Status runPass(const MeasureOptions& o, Pass& p, std::uint32_t index) {
    for (std::uint64_t f = 0; f < o.frames; ++f) {
        if (Status s = p.runner->runFrame(o.firstFrame + f * o.stride); !s) return s;
        if (!o.quiet && ((f + 1) % 10 == 0 || f + 1 == o.frames)) {
            std::fprintf(stderr, "%sframe %llu/%llu\n", o.passes > 1 ? ("pass " + std::to_string(index + 1) + ", ").c_str() : "",
                         static_cast<unsigned long long>(f + 1), static_cast<unsigned long long>(o.frames));
        }
    }
    if (p.context->checkErrors() != 0)
        std::fprintf(stderr, "warning: %llu GL errors\n", static_cast<unsigned long long>(p.context->glErrorCount()));
    return {};
}

}  // namespace

Status runMeasurement(const MeasureOptions& o, std::vector<ModeSpec> modes, const std::string& command,
                      std::vector<ModeSummary>* summaryOut) {
    if (o.size.x < 1 || o.size.y < 1) return Error{"--size: width and height must be at least 1"};
    if (o.frames == 0) return Error{"--frames: must be at least 1"};
    if (o.stride == 0) return Error{"--stride: must be at least 1"};
    if (o.passes == 0) return Error{"--passes: must be at least 1"};
    // The later passes first, each set up afresh and torn down, then the first, whose
    // runner writes everything but the times it took the least of.
    std::vector<BenchResult> later;
    for (std::uint32_t pass = 1; pass < o.passes; ++pass) {
        auto p = startPass(o, modes, false);
        if (!p) return p.error();
        p->runner->setOrderOffset(pass);
        if (Status s = runPass(o, *p, pass); !s) return s;
        later.push_back(p->runner->result());
    }
    auto first = startPass(o, std::move(modes), true);
    if (!first) return first.error();
    Pass& pass = *first;
    const std::filesystem::path dir = o.out.empty() ? "out/measure_" + pass.scene->name() : o.out;
    std::error_code ec;
    std::filesystem::create_directories(dir, ec);
    if (ec) return Error{dir.string() + ": cannot create directory (" + ec.message() + ")"};
    if (Status s = runPass(o, pass, 0); !s) return s;
    for (const BenchResult& r : later) pass.runner->keepFastest(r);
    const std::unique_ptr<BenchRunner>& runner = pass.runner;
    runner->measureLeafVolumes();

    const BenchResult& result = runner->result();
    const std::vector<ModeSummary> summary = summarise(result);
    if (Status s = writeFramesCsv(result, dir / "frames.csv"); !s) return s;
    if (Status s = writeSummaryCsv(summary, dir / "summary.csv"); !s) return s;
    if (result.streaming.frames > 0)
        if (Status s = result.streaming.writeCsv(dir / "streaming.csv"); !s) return s;
    for (std::size_t m = 0; m < result.modes.size(); ++m) {
        const std::filesystem::path png = dir / ("last_" + result.modes[m].name + ".png");
        if (Status s = writePng(runner->lastImages()[m], png); !s) return s;
    }
    const PlotOutcome plots = writePlots(result, summary, dir);
    if (!plots.message.empty()) std::printf("%s\n", plots.message.c_str());
    const std::string streamingLine = result.streaming.frames > 0 ? result.streaming.line(o.sceneOptions.stream) : "";
    if (Status s = writeReport(result, summary, command, plots.pngs, streamingLine, dir / "report.md"); !s) return s;
    if (!streamingLine.empty()) std::printf("streaming stats: %s\n%s\n", (dir / "streaming.csv").c_str(), streamingLine.c_str());
    std::printf("wrote %s, %s, %s", (dir / "frames.csv").c_str(), (dir / "summary.csv").c_str(),
                (dir / "report.md").c_str());
    for (const std::string& p : plots.pngs) std::printf(", %s", (dir / p).c_str());
    std::printf("\n");
    std::printf("%-20s %9s %8s %8s %9s %9s %10s %6s\n", "mode", "ms/frame", "vs vfc", "parts", "queries", "%px wrong",
                "false neg", "t/o");
    for (const ModeSummary& s : summary)
        std::printf("%-20s %9.2f %8.2f %8.1f %9.1f %9.4f %10llu %6llu\n", s.name.c_str(), s.msMean, s.ratioVfc, s.parts,
                    s.queries, s.pctWrongMean, static_cast<unsigned long long>(s.falseNegatives),
                    static_cast<unsigned long long>(s.timeouts));
    if (summaryOut) *summaryOut = summary;
    return {};
}

}  // namespace dyncull::cli
