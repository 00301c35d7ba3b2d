// `dyncull bench --modes` names: presets, ablations and '+' combinations map to the
// scheduler and query settings they promise; bad names are errors naming the culprit.
#include <gtest/gtest.h>

#include "bench_runner.hpp"

namespace dyncull::cli {
namespace {

TEST(BenchModes, BaseModes) {
    EXPECT_EQ(modeFromName("vfc")->scheduler.mode, CullMode::Vfc);
    EXPECT_EQ(modeFromName("simple")->scheduler.mode, CullMode::Simple);
    EXPECT_TRUE(modeFromName("oracle")->oracle);
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
    EXPECT_TRUE(modeFromName("vfc")->scheduler.features.useClusters);
    EXPECT_FALSE(modeFromName("vfc-noclusters")->scheduler.features.useClusters);
    EXPECT_EQ(modeFromName("vfc-noclusters")->scheduler.mode, CullMode::Vfc);
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

}  // namespace
}  // namespace dyncull::cli
