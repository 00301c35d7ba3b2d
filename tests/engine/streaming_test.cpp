// Streamed models drawn by StreamedObjects: under budgets far below the model, the images
// are the in-core ones pixel for pixel, both budgets hold on every frame, stalls and late
// leaves are counted, and a corrupt leaf is an error of the frame, not a crash.
#include <gtest/gtest.h>

#include <fstream>

#include "dyncull/engine/engine.hpp"
#include "dyncull/engine/streamed_objects.hpp"
#include "dyncull/streaming/out_of_core_subdivision.hpp"
#include "engine/gl_test_util.hpp"
#include "objects/test_files.hpp"
#include "streaming/streamed_test_models.hpp"

namespace dyncull {
namespace {

constexpr int kSize = 96;

/// An orbit around the field, low enough that the near spheres hide the far ones.
Camera orbit(int frame) {
    Camera c;
    const float a = 0.15f * static_cast<float>(frame);
    c.position = glm::vec3(6.0f, 1.5f, 6.0f) + glm::vec3(9.0f * std::cos(a), 0.0f, 9.0f * std::sin(a));
    c.target = {6.0f, 1.0f, 6.0f};
    c.aspect = 1.0f;
    c.nearPlane = 0.1f;
    c.farPlane = 100.0f;
    return c;
}

class Streaming : public ::testing::Test {
protected:
    void SetUp() override {
        const Mesh field = test::sphereField(5, 12, 16);  // 50 spheres, 19,200 triangles
        OutOfCoreParams p;
        p.subdivision.maxLeafTriangles = 200;
        p.memoryBytes = std::size_t{16} << 20;
        auto built = subdivideOutOfCore(meshSource(field), dir_.file("field.dnodes"), p);
        ASSERT_TRUE(built.ok()) << built.error().message;
        leaves_ = built->leaves;
        total_ = built->geometryBytes;
    }

    struct Run {
        std::vector<Image> images;
        std::vector<StreamingFrameStats> frames;
        std::string error;
    };
    Run render(const StreamingOptions& options, int frames) {
        Run run;
        auto ctx = test::headless(kSize, kSize);
        if (!ctx) return run;
        auto engine = Engine::create(*ctx);
        EXPECT_TRUE(engine.ok());
        auto objects = StreamedObjects::create(**engine, dir_.file("field.dnodes"), options);
        EXPECT_TRUE(objects.ok()) << objects.error().message;
        if (!objects.ok()) return run;
        for (int f = 0; f < frames; ++f) {
            const Camera c = orbit(f);
            EXPECT_TRUE((*engine)->setCamera(c).ok());
            (*objects)->beginFrame(c);
            ctx->clearFramebuffer(Renderer::kClearColour);
            EXPECT_TRUE((*engine)->renderFrame().ok());
            auto s = (*objects)->endFrame();
            if (!s) {
                if (run.error.empty()) run.error = s.error().message;
                continue;
            }
            run.frames.push_back(*s);
            run.images.push_back((*engine)->renderer().readPixels());
        }
        return run;
    }

    test::TempDir dir_;
    std::uint32_t leaves_ = 0;
    std::uint64_t total_ = 0;
};

TEST_F(Streaming, TinyBudgetsGiveTheInCoreImagesAndHold) {
    StreamingOptions inCore;
    inCore.memoryBytes = 0;
    inCore.gpuBytes = 0;
    const Run reference = render(inCore, 12);
    ASSERT_EQ(reference.images.size(), 12u);
    int covered = 0;
    for (int y = 0; y < kSize; ++y)
        for (int x = 0; x < kSize; ++x) covered += !test::isClear(reference.images[0].at(x, y));
    EXPECT_GT(covered, kSize * kSize / 5) << "the field fills much of the picture";
    StreamingOptions tiny;
    tiny.memoryBytes = total_ / 8;  // an eighth of the model in memory
    tiny.gpuBytes = total_ / 12;    // less in GL buffers than one frame draws
    const Run streamed = render(tiny, 12);
    ASSERT_EQ(streamed.images.size(), 12u) << streamed.error;
    std::uint64_t loads = 0, overflow = 0;
    for (std::size_t f = 0; f < streamed.images.size(); ++f) {
        EXPECT_TRUE(streamed.images[f].rgba == reference.images[f].rgba) << "frame " << f;
        const StreamingFrameStats& s = streamed.frames[f];
        EXPECT_LE(s.memoryResidentBytes, tiny.memoryBytes);
        EXPECT_LE(s.gpuResidentBytes, tiny.gpuBytes);
        EXPECT_EQ(s.late, 0u) << "waiting draws every leaf";
        loads += s.loads;
        overflow += s.overflow;
    }
    EXPECT_GT(loads, leaves_) << "the budget forces leaves to be read again";
    EXPECT_GT(overflow, 0u) << "a GL budget below one frame's leaves draws from transient copies";
}

TEST_F(Streaming, LateLeavesAreCountedWhenNotWaitedFor) {
    StreamingOptions skip;
    skip.memoryBytes = total_ / 8;
    skip.gpuBytes = 0;
    skip.late = StreamLate::Skip;
    const Run run = render(skip, 3);
    ASSERT_EQ(run.frames.size(), 3u);
    EXPECT_GT(run.frames[0].late, 0u) << "nothing is resident before the first frame";
    EXPECT_EQ(run.frames[0].stallMs, 0.0);
}

TEST_F(Streaming, ACorruptLeafIsAnErrorOfTheFrameNamingIt) {
    const auto geometry = geometryPathFor(dir_.file("field.dnodes"));
    std::string bytes;
    {
        std::ifstream f(geometry, std::ios::binary);
        bytes.assign(std::istreambuf_iterator<char>(f), {});
    }
    for (std::size_t i = kStreamedHeaderSize; i < bytes.size(); i += 64) bytes[i] = static_cast<char>(bytes[i] ^ 0x20);
    std::ofstream(geometry, std::ios::binary) << bytes;
    StreamingOptions o;
    o.memoryBytes = total_;
    const Run run = render(o, 2);
    EXPECT_NE(run.error.find("leaf "), std::string::npos) << run.error;
    EXPECT_NE(run.error.find(geometry.string()), std::string::npos) << run.error;
}

TEST_F(Streaming, BudgetsBelowOneLeafAreRefused) {
    auto ctx = test::headless(kSize, kSize);
    ASSERT_TRUE(ctx);
    auto engine = Engine::create(*ctx);
    ASSERT_TRUE(engine.ok());
    StreamingOptions o;
    o.memoryBytes = 16;
    auto r = StreamedObjects::create(**engine, dir_.file("field.dnodes"), o);
    ASSERT_FALSE(r.ok());
    EXPECT_NE(r.error().message.find("budget"), std::string::npos) << r.error().message;
    o.memoryBytes = total_;
    o.gpuBytes = 16;
    EXPECT_FALSE(StreamedObjects::create(**engine, dir_.file("field.dnodes"), o).ok());
    EXPECT_FALSE(StreamedObjects::create(**engine, dir_.file("missing.dnodes"), StreamingOptions{}).ok());
}

}  // namespace
}  // namespace dyncull
