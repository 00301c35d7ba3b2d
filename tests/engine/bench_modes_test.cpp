// `dyncull bench --modes` names: presets, ablations and '+' combinations map to the
// scheduler and query settings they promise; bad names are errors naming the culprit.
#include <gtest/gtest.h>

#include "bench_runner.hpp"
#include "report_writer.hpp"

namespace dyncull::cli {
namespace {

TEST(BenchModes, BaseModes) {
    EXPECT_EQ(modeFromName("vfc")->scheduler.mode, CullMode::Vfc);
    EXPECT_EQ(modeFromName("simple")->scheduler.mode, CullMode::Simple);
    EXPECT_TRUE(modeFromName("oracle")->oracle);
    EXPECT_FALSE(modeFromName("oracle")->oracleClusters);
    EXPECT_TRUE(modeFromName("oracle-clusters")->oracle && modeFromName("oracle-clusters")->oracleClusters);
    EXPECT_EQ(modeFromName("oracle-clusters")->oracleBudgetPercent, 0.0);
    EXPECT_TRUE(modeFromName("oracle-boxes")->oracle && modeFromName("oracle-boxes")->oracleBoxes);
    EXPECT_FALSE(modeFromName("oracle-boxes")->oracleClusters);
    const ModeSpec budgetOracle = modeFromName("oracle-budget0.1").take();
    EXPECT_TRUE(budgetOracle.oracle && budgetOracle.oracleClusters);
    EXPECT_DOUBLE_EQ(budgetOracle.oracleBudgetPercent, 0.1);
    EXPECT_FALSE(modeFromName("oracle-budget0"));
    EXPECT_FALSE(modeFromName("oracle-budget"));
    const ModeSpec full = modeFromName("full").take();
    EXPECT_EQ(full.scheduler.mode, CullMode::TwoPhase);
    EXPECT_TRUE(full.scheduler.features.useBatchedRaster && full.scheduler.features.useCostModel && full.scheduler.features.useHistory);
    EXPECT_EQ(full.scheduler.mode, SchedulerParams{}.mode) << "full is the library's default";
    const ModeSpec queries = modeFromName("queries").take();
    EXPECT_EQ(queries.scheduler.mode, CullMode::Queries);
    EXPECT_EQ(queries.queries.visiblePixelThreshold, 0u);  // conservative by default
    EXPECT_FALSE(queries.scheduler.approx.useLastFrameResults);
}

TEST(BenchModes, AblationsOfFullAndTheirVolumes) {
    EXPECT_FALSE(modeFromName("full-hzb")->scheduler.features.useBatchedRaster);
    EXPECT_FALSE(modeFromName("full-nohist")->scheduler.features.useHistory);
    EXPECT_FALSE(modeFromName("full-nocost")->scheduler.features.useCostModel);
    EXPECT_FALSE(modeFromName("full")->scheduler.features.useTriangleTests);
    EXPECT_TRUE(modeFromName("full-tri")->scheduler.features.useTriangleTests);
    EXPECT_TRUE(modeFromName("full")->scheduler.features.useClusters);
    EXPECT_FALSE(modeFromName("full-noclusters")->scheduler.features.useClusters);
    EXPECT_TRUE(modeFromName("full")->scheduler.features.useClusterHistory);
    EXPECT_FALSE(modeFromName("full-noclusterhist")->scheduler.features.useClusterHistory);
    EXPECT_TRUE(modeFromName("full-noclusterhist")->scheduler.features.useClusters);
    EXPECT_FALSE(modeFromName("full")->scheduler.features.useClusterMarks);
    EXPECT_TRUE(modeFromName("full-markclusterhist")->scheduler.features.useClusterMarks);
    EXPECT_TRUE(modeFromName("full-markclusterhist")->scheduler.features.useClusterHistory);
    EXPECT_TRUE(modeFromName("full")->scheduler.features.useClusterWorker);
    EXPECT_FALSE(modeFromName("full-noworker")->scheduler.features.useClusterWorker);
    EXPECT_TRUE(modeFromName("vfc")->scheduler.features.useClusters);
    EXPECT_FALSE(modeFromName("vfc-noclusters")->scheduler.features.useClusters);
    EXPECT_EQ(modeFromName("vfc-noclusters")->scheduler.mode, CullMode::Vfc);
    EXPECT_EQ(modeFromName("vfc-again")->scheduler.mode, CullMode::Vfc);  // the noise floor: vfc again
    EXPECT_TRUE(modeFromName("vfc-again")->scheduler.features.useClusters);
    EXPECT_TRUE(modeFromName("full")->scheduler.features.useEndProbes);
    EXPECT_FALSE(modeFromName("full-testprobe")->scheduler.features.useEndProbes);
    EXPECT_TRUE(modeFromName("full")->scheduler.features.useRefreshPyramid);
    EXPECT_FALSE(modeFromName("full-rasterrefresh")->scheduler.features.useRefreshPyramid);
    EXPECT_TRUE(modeFromName("full")->scheduler.features.useLearnedClusters);
    EXPECT_FALSE(modeFromName("full-ownrecord")->scheduler.features.useLearnedClusters);
    EXPECT_TRUE(modeFromName("full")->scheduler.features.useObbFrames);
    EXPECT_FALSE(modeFromName("full-obbpoints")->scheduler.features.useObbFrames);
    EXPECT_TRUE(modeFromName("full")->scheduler.features.useLatePyramid);
    EXPECT_FALSE(modeFromName("full-nolatepyramid")->scheduler.features.useLatePyramid);
    EXPECT_GT(modeFromName("full")->scheduler.tuning.texelTestTexels, 0);
    EXPECT_EQ(modeFromName("full-notexel")->scheduler.tuning.texelTestTexels, 0);
    EXPECT_EQ(modeFromName("full-notexel")->scheduler.tuning.clusterTexelTests, 0);
    const ModeSpec k = modeFromName("full+kdop26").take();
    EXPECT_EQ(k.scheduler.mode, CullMode::TwoPhase);
    EXPECT_EQ(k.scheduler.tuning.volume, VolumeChoice::Kdop26);
    // Settings of queries do not combine with full, either way round.
    for (const char* bad : {"full+thr16", "thr16+full", "full+full-hzb"}) {
        auto m = modeFromName(bad);
        ASSERT_FALSE(m) << bad;
        EXPECT_NE(m.error().message.find("does not combine"), std::string::npos) << m.error().message;
    }
}

TEST(BenchModes, PresetsSetOneThing) {
    EXPECT_EQ(modeFromName("thr16")->queries.visiblePixelThreshold, 16u);
    EXPECT_EQ(modeFromName("small4")->scheduler.approx.smallFeaturePixels, 4u);
    EXPECT_TRUE(modeFromName("latency1")->scheduler.approx.useLastFrameResults);
    EXPECT_TRUE(modeFromName("overlap")->scheduler.approx.batchOverlapping);
    EXPECT_FALSE(modeFromName("queries-nohist")->scheduler.features.useHistory);
    EXPECT_EQ(modeFromName("skip20")->scheduler.tuning.history.maxSkipFrames, 20u);
    const ModeSpec budget = modeFromName("budget0.1").take();
    EXPECT_EQ(budget.scheduler.mode, CullMode::TwoPhase);
    EXPECT_DOUBLE_EQ(budget.scheduler.approx.errorBudgetPercent, 0.1);
    EXPECT_FALSE(budget.scheduler.approx.budgetEarlySet);
    EXPECT_FALSE(budget.scheduler.approx.budgetRecount);
    EXPECT_TRUE(modeFromName("budgetearly0.5")->scheduler.approx.budgetEarlySet);
    EXPECT_TRUE(modeFromName("budgetrecount0.5")->scheduler.approx.budgetRecount);
    EXPECT_EQ(modeFromName("full")->scheduler.approx.errorBudgetPercent, 0.0);
    // A budget is a percentage in (0, 100], written as a plain decimal.
    for (const char* bad : {"budget0", "budget-1", "budget101", "budget1e-3", "budget", "budget0.1x", "budget0.1+thr16"})
        EXPECT_FALSE(modeFromName(bad)) << bad;
}

TEST(BenchModes, SettingsCombineWithPlus) {
    const ModeSpec m = modeFromName("thr16+latency1+queries-noocc").take();
    EXPECT_EQ(m.name, "thr16+latency1+queries-noocc");
    EXPECT_EQ(m.scheduler.mode, CullMode::Queries);
    EXPECT_EQ(m.queries.visiblePixelThreshold, 16u);
    EXPECT_TRUE(m.scheduler.approx.useLastFrameResults);
    EXPECT_FALSE(m.scheduler.features.useOccupancyAccept);
    EXPECT_TRUE(m.scheduler.features.useHistory);
}

TEST(BenchModes, BadNamesAreErrorsNamingThePart) {
    for (const char* bad : {"", "thr", "thrx", "vfc+thr16", "thr16+", "+thr16", "thr16+bogus", "fast"}) {
        auto m = modeFromName(bad);
        ASSERT_FALSE(m) << bad;
        EXPECT_NE(m.error().message.find("unknown mode"), std::string::npos) << m.error().message;
    }
    EXPECT_NE(modeFromName("thr16+bogus").error().message.find("'bogus'"), std::string::npos);
    EXPECT_FALSE(modesFromList("full,full"));
    EXPECT_FALSE(modesFromList("full,,vfc"));
    EXPECT_EQ(modesFromList("vfc,full,thr16+latency1")->size(), 3u);
}

TEST(BenchModes, FamiliesNameTheApproximations) {
    for (const char* conservative : {"vfc", "full", "queries", "full-hzb", "front20", "oracle"})
        EXPECT_EQ(modeFromName(conservative)->family, "") << conservative;
    EXPECT_EQ(modeFromName("budget0.1")->family, "error budget");
    EXPECT_EQ(modeFromName("budgetearly0.1")->family, "error budget, early set");
    EXPECT_EQ(modeFromName("budgetrecount0.1")->family, "error budget, recount");
    EXPECT_EQ(modeFromName("thr16")->family, "sample threshold");
    EXPECT_EQ(modeFromName("small16")->family, "small features");
    EXPECT_EQ(modeFromName("latency1")->family, "latency");
    EXPECT_EQ(modeFromName("thr16+latency1")->family, "sample threshold + latency");
}

TEST(BenchModes, EverySweptValueIsInItsParametersFamily) {
    auto budget = sweepModes("error-budget=0.05,0.5");
    ASSERT_TRUE(budget) << budget.error().message;
    ASSERT_EQ(budget->size(), 2u);
    EXPECT_EQ((*budget)[0].name, "error-budget=0.05");
    for (const ModeSpec& m : *budget) EXPECT_EQ(m.family, "error budget");
    // The conservative end of a curve (0) stays on its family's curve.
    auto threshold = sweepModes("pixel-threshold=0,16");
    ASSERT_TRUE(threshold);
    for (const ModeSpec& m : *threshold) EXPECT_EQ(m.family, "sample threshold");
    auto latency = sweepModes("latency=0,1");
    ASSERT_TRUE(latency);
    EXPECT_FALSE((*latency)[0].scheduler.approx.useLastFrameResults);
    EXPECT_TRUE((*latency)[1].scheduler.approx.useLastFrameResults);
    EXPECT_EQ((*latency)[1].family, "latency");
    EXPECT_EQ(sweepModes("max-skip=2,4")->front().family, "max-skip");
    auto testNs = sweepModes("test-ns=2700,5000");
    ASSERT_TRUE(testNs) << testNs.error().message;
    EXPECT_EQ((*testNs)[1].scheduler.mode, CullMode::TwoPhase);
    EXPECT_EQ((*testNs)[1].scheduler.tuning.costs.testNsPerVolume, 5000.0);
    EXPECT_FALSE(sweepModes("latency=2"));
    EXPECT_FALSE(sweepModes("error-budget=0.1,0.1"));
}

// Each family's curve is its own Pareto front: a setting another of the same family beats
// on time and error is off the curve, even if it beats every other family.
TEST(BenchModes, EachFamilysCurveIsItsOwnFront) {
    BenchResult r;
    r.width = 100;
    r.height = 10;
    const std::vector<std::pair<std::string, std::pair<double, double>>> modes = {
        {"vfc", {10.0, 0.0}},         {"full", {6.0, 0.0}},        {"budget0.1", {5.0, 0.05}},
        {"budget0.5", {5.5, 0.2}},    {"budget1", {4.0, 0.4}},     {"thr16", {4.5, 0.45}},
        {"thr64", {3.0, 1.0}}};
    std::vector<ModeFrame> row;
    for (const auto& [name, timeAndError] : modes) {
        r.modes.push_back(modeFromName(name).take());
        ModeFrame f;
        f.stats.frameMs = timeAndError.first;
        f.image.percentDiffering = timeAndError.second;
        row.push_back(f);
    }
    r.frames.push_back(row);
    r.truth.resize(1);
    const std::vector<ModeSummary> s = summarise(r);
    auto at = [&](const char* name) { return s[std::size_t(findMode(s, name))]; };
    EXPECT_TRUE(at("budget0.1").familyFront);
    EXPECT_FALSE(at("budget0.5").familyFront) << "slower and worse than budget0.1";
    EXPECT_TRUE(at("budget1").familyFront);
    EXPECT_TRUE(at("thr16").familyFront) << "budget1 beats it, but is of another family";
    EXPECT_FALSE(at("thr16").pareto);
    EXPECT_TRUE(at("thr64").familyFront && at("thr64").pareto);
    EXPECT_FALSE(at("full").familyFront) << "conservative modes are no family's curve";
    EXPECT_TRUE(at("full").pareto);
}

// Each frame's ratio to vfc, over frames 1 and up: the median, the 95th percentile by
// nearest rank and the worst frame, which the "95th percentile" target reads.
TEST(BenchReport, EachFrameAgainstVfcSkipsTheFirstFrame) {
    BenchResult r;
    r.width = 100;
    r.height = 10;
    for (const char* name : {"vfc", "full"}) r.modes.push_back(modeFromName(name).take());
    // Frame 0 at 100x, then frames 1..20 at ratios 0.5, 0.55, ..., 1.45 in shuffled order.
    for (std::size_t k = 0; k <= 20; ++k) {
        std::vector<ModeFrame> row(2);
        row[0].stats.frameMs = 10.0;
        const std::size_t rank = k == 0 ? 0 : (k * 7) % 20;  // 7 is coprime with 20: a permutation
        row[1].stats.frameMs = k == 0 ? 1000.0 : 10.0 * (0.5 + 0.05 * double(rank));
        r.frames.push_back(row);
    }
    r.truth.resize(r.frames.size());
    const std::vector<ModeSummary> s = summarise(r);
    const ModeSummary& full = s[std::size_t(findMode(s, "full"))];
    EXPECT_NEAR(full.vfcRatioMedian, 0.5 * (0.95 + 1.0), 1e-9);
    EXPECT_NEAR(full.vfcRatioP95, 1.40, 1e-9) << "the 19th of 20";
    EXPECT_NEAR(full.vfcRatioMax, 1.45, 1e-9);
    EXPECT_EQ(full.vfcRatioMaxFrame, 17u) << "17 * 7 = 119: rank 19";
    EXPECT_NEAR(s[std::size_t(findMode(s, "vfc"))].vfcRatioP95, 1.0, 1e-12);
}

}  // namespace
}  // namespace dyncull::cli
