// Shared rig of the numerical-extremes tests: an engine with a vfc and a conservative full
// scheduler, the ID-pass ground truth, rendering one frame with
// each scheduler and comparing images and parts.
#pragma once

#include <gtest/gtest.h>

#include <memory>
#include <string>

#include "dyncull/engine/engine.hpp"
#include "dyncull/measure/ground_truth.hpp"
#include "dyncull/measure/image_compare.hpp"
#include "engine/gl_test_util.hpp"

namespace dyncull::test {

inline constexpr int kWidth = 160, kHeight = 120;

/// An engine with a vfc scheduler and the two conservative occlusion modes (full, which is
/// two-phase, and queries) and the ground truth.
struct Rig {
    std::unique_ptr<GlContext> ctx;
    std::unique_ptr<Engine> engine;
    std::unique_ptr<GroundTruth> truth;
    QueryScheduler vfc{[] {
        SchedulerParams p;
        p.mode = CullMode::Vfc;
        return p;
    }()};
    QueryScheduler queries{[] {
        SchedulerParams p;
        p.mode = CullMode::Queries;
        p.tuning.queryTimeoutMs = 20000.0;  // culling is checked here, not latency
        return p;
    }()};
    QueryScheduler full{[] {
        SchedulerParams p;  // the default: two-phase
        p.tuning.queryTimeoutMs = 20000.0;
        // These scenes are tiny: the cost model would find the tests dearer than the
        // drawing they save and switch them off, and the tests are what is checked here.
        p.features.useCostModel = false;
        return p;
    }()};

    Rig() {
        ctx = headless(kWidth, kHeight);
        if (!ctx) return;
        auto e = Engine::create(*ctx);
        EXPECT_TRUE(e.ok()) << e.error().message;
        engine = e.take();
        auto t = GroundTruth::create(*ctx);
        EXPECT_TRUE(t.ok());
        truth = t.take();
    }
    bool ok() const { return engine && truth; }
    ModelId model(const Mesh& m, const LocalBspParams& params = {}) {
        auto id = engine->addModel(m, params);
        EXPECT_TRUE(id.ok()) << id.error().message;
        return id.ok() ? *id : 0;
    }
    ObjectHandle object(ModelId m, const glm::vec3& at, const glm::vec3& scale = glm::vec3(1.0f)) {
        Transform t;
        t.translation = at;
        t.scale = scale;
        auto h = engine->addObject(m, t);
        EXPECT_TRUE(h.ok()) << h.error().message;
        return h.ok() ? *h : ObjectHandle{};
    }

    struct Result {
        Image vfcImage, queriesImage, fullImage;
        ImageDiff diff, fullDiff;          // queries and full against vfc
        PartErrors errors, fullErrors;     // queries and full against the ground truth
        FrameStats vfcStats, queriesStats, fullStats;
        std::vector<NodeRef> fullDrawn;     // the leaves full drew (drawnLeaves)
        std::vector<NodeRef> queriesDrawn;  // the leaves queries drew
        std::uint32_t visibleParts = 0;
    };
    /// One frame with vfc and queries from `camera`; full renders two, since it decides
    /// from the frame before (the first one draws what its tests cannot reject against an
    /// empty depth buffer), and the second is checked.
    Result frame(const Camera& camera) {
        Result r;
        EXPECT_TRUE(engine->setCamera(camera).ok());
        ctx->clearFramebuffer(Renderer::kClearColour);
        r.vfcStats = *engine->renderFrame(vfc);
        r.vfcImage = engine->renderer().readPixels();
        ctx->clearFramebuffer(Renderer::kClearColour);
        EXPECT_TRUE(engine->renderFrame(full).ok());
        ctx->clearFramebuffer(Renderer::kClearColour);
        r.fullStats = *engine->renderFrame(full);
        r.fullImage = engine->renderer().readPixels();
        r.fullDrawn = drawnLeaves(engine->objects(), engine->visibleParts());
        ctx->clearFramebuffer(Renderer::kClearColour);
        r.queriesStats = *engine->renderFrame(queries);
        r.queriesImage = engine->renderer().readPixels();
        r.queriesDrawn = drawnLeaves(engine->objects(), engine->visibleParts());
        auto d = compareImages(r.vfcImage, r.queriesImage);
        auto f = compareImages(r.vfcImage, r.fullImage);
        EXPECT_TRUE(d.ok() && f.ok());
        r.diff = *d;
        r.fullDiff = *f;
        const VisibleSet vis = truth->compute(*engine, camera);
        r.visibleParts = static_cast<std::uint32_t>(vis.parts.size());
        r.errors = compareParts(vis, r.queriesDrawn);
        r.fullErrors = compareParts(vis, r.fullDrawn);
        EXPECT_EQ(ctx->checkErrors(), 0u);
        return r;
    }
};

inline Camera look(const glm::vec3& from, const glm::vec3& at, float nearPlane = 0.05f, float farPlane = 1000.0f) {
    Camera c;
    c.position = from;
    c.target = at;
    c.aspect = static_cast<float>(kWidth) / static_cast<float>(kHeight);
    c.nearPlane = nearPlane;
    c.farPlane = farPlane;
    return c;
}

/// Both conservative modes must be exact against vfc and the ground truth.
inline void expectConservative(const Rig::Result& r, const std::string& what) {
    EXPECT_LE(r.diff.percentDiffering, 0.01) << what << " (queries)";
    EXPECT_EQ(r.errors.falseNegatives, 0u) << what << " (queries)";
    EXPECT_EQ(r.queriesStats.queriesTimedOut, 0u) << what << " (queries)";
    EXPECT_LE(r.fullDiff.percentDiffering, 0.01) << what << " (full)";
    EXPECT_EQ(r.fullErrors.falseNegatives, 0u) << what << " (full)";
}

inline std::uint64_t nonBackground(const Image& img) {
    std::uint64_t n = 0;
    for (std::size_t i = 0; i < img.rgba.size(); i += 4)
        if (!isClear({img.rgba[i], img.rgba[i + 1], img.rgba[i + 2], img.rgba[i + 3]})) ++n;
    return n;
}

}  // namespace dyncull::test
