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
    EXPECT_TRUE(full.scheduler.useBatchedRaster && full.scheduler.useCostModel && full.scheduler.useHistory);
    EXPECT_EQ(full.scheduler.mode, SchedulerParams{}.mode) << "full is the library's default";
    const ModeSpec queries = modeFromName("queries").take();
    EXPECT_EQ(queries.scheduler.mode, CullMode::Queries);
    EXPECT_EQ(queries.queries.visiblePixelThreshold, 0u);  // conservative by default
    EXPECT_FALSE(queries.scheduler.useLastFrameResults);
}

TEST(BenchModes, AblationsOfFullAndTheirVolumes) {
    EXPECT_FALSE(modeFromName("full-hzb")->scheduler.useBatchedRaster);
    EXPECT_FALSE(modeFromName("full-nohist")->scheduler.useHistory);
    EXPECT_FALSE(modeFromName("full-nocost")->scheduler.useCostModel);
    EXPECT_FALSE(modeFromName("full")->scheduler.useTriangleTests);
    EXPECT_TRUE(modeFromName("full-tri")->scheduler.useTriangleTests);
    EXPECT_TRUE(modeFromName("full")->scheduler.useClusters);
    EXPECT_FALSE(modeFromName("full-noclusters")->scheduler.useClusters);
    EXPECT_TRUE(modeFromName("vfc")->scheduler.useClusters);
    EXPECT_FALSE(modeFromName("vfc-noclusters")->scheduler.useClusters);
    EXPECT_EQ(modeFromName("vfc-noclusters")->scheduler.mode, CullMode::Vfc);
    const ModeSpec k = modeFromName("full+kdop26").take();
    EXPECT_EQ(k.scheduler.mode, CullMode::TwoPhase);
    EXPECT_EQ(k.scheduler.volume, VolumeChoice::Kdop26);
    // Settings of queries do not combine with full, either way round.
    for (const char* bad : {"full+thr16", "thr16+full", "full+full-hzb"}) {
        auto m = modeFromName(bad);
        ASSERT_FALSE(m) << bad;
        EXPECT_NE(m.error().message.find("does not combine"), std::string::npos) << m.error().message;
    }
}

TEST(BenchModes, PresetsSetOneThing) {
    EXPECT_EQ(modeFromName("thr16")->queries.visiblePixelThreshold, 16u);
    EXPECT_EQ(modeFromName("small4")->scheduler.smallFeaturePixels, 4u);
    EXPECT_TRUE(modeFromName("latency1")->scheduler.useLastFrameResults);
    EXPECT_TRUE(modeFromName("overlap")->scheduler.batchOverlapping);
    EXPECT_FALSE(modeFromName("queries-nohist")->scheduler.useHistory);
    EXPECT_EQ(modeFromName("skip20")->scheduler.history.maxSkipFrames, 20u);
}

TEST(BenchModes, SettingsCombineWithPlus) {
    const ModeSpec m = modeFromName("thr16+latency1+queries-noocc").take();
    EXPECT_EQ(m.name, "thr16+latency1+queries-noocc");
    EXPECT_EQ(m.scheduler.mode, CullMode::Queries);
    EXPECT_EQ(m.queries.visiblePixelThreshold, 16u);
    EXPECT_TRUE(m.scheduler.useLastFrameResults);
    EXPECT_FALSE(m.scheduler.useOccupancyAccept);
    EXPECT_TRUE(m.scheduler.useHistory);
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
