// Scheduler state-machine tests with scripted backends (no GL): latency, timeouts,
// conservative handling of near-plane boxes, history skipping and batching rules.
// Image-level correctness against vfc is tested with real GL in tests/engine.
#include <gtest/gtest.h>

#include <algorithm>
#include <functional>
#include <map>
#include <set>

#include "dyncull/bsp/loose_bsp.hpp"
#include "dyncull/bsp/scene_objects.hpp"
#include "dyncull/bsp/traversal.hpp"
#include "dyncull/scheduler/query_scheduler.hpp"

using namespace dyncull;

namespace {

LocalBsp cubeModel(float half) {
    // A single-leaf local BSP over a 12-triangle cube.
    LocalBsp bsp;
    Mesh& m = bsp.mesh;
    for (int i = 0; i < 8; ++i)
        m.positions.push_back({(i & 1) ? half : -half, (i & 2) ? half : -half, (i & 4) ? half : -half});
    const std::uint32_t idx[36] = {0, 2, 1, 1, 2, 3, 4, 5, 6, 5, 7, 6, 0, 1, 4, 1, 5, 4,
                                   2, 6, 3, 3, 6, 7, 0, 4, 2, 2, 4, 6, 1, 3, 5, 3, 7, 5};
    m.indices.assign(idx, idx + 36);
    computeNormals(m);
    LocalBspNode root;
    root.box = m.bounds();
    root.firstIndex = 0;
    root.indexCount = 36;
    bsp.nodes.push_back(root);
    bsp.stats.trianglesBefore = bsp.stats.trianglesAfter = 12;
    bsp.stats.leaves = 1;
    return bsp;
}

struct TestScene {
    SceneObjects objects;
    LooseBsp bsp;
    std::vector<ObjectHandle> handles;

    // A grid of cubes along -Z in front of a camera at the origin looking down -Z.
    explicit TestScene(int nx, int nz) {
        const ModelId cube = objects.addModel(cubeModel(0.4f));
        for (int z = 0; z < nz; ++z)
            for (int x = 0; x < nx; ++x) {
                Transform t;
                t.translation = {static_cast<float>(x) - 0.5f * static_cast<float>(nx - 1), 0.0f, -3.0f - 2.0f * static_cast<float>(z)};
                handles.push_back(objects.addObject(cube, t).take());
            }
        bsp.build(objects);
    }
};

Camera frontCamera() {
    Camera c;
    c.position = {0.0f, 0.0f, 0.0f};
    c.target = {0.0f, 0.0f, -1.0f};
    c.nearPlane = 0.1f;
    c.farPlane = 100.0f;
    c.aspect = 2.0f;
    return c;
}

struct RecordingSink final : PartSink {
    std::multiset<std::uint32_t> drawn;
    void drawPart(std::uint32_t object, std::uint32_t, std::uint32_t) override { drawn.insert(object); }
};

// Answers by a rule after `latency` polls; can also never answer.
struct ScriptedBackend final : QueryBackend {
    std::function<QueryResult(const QueryVolume&)> rule = [](const QueryVolume&) { return QueryResult::Visible; };
    int latency = 0;
    bool neverAnswer = false;
    struct Q { QueryVolume v; int polls = 0; bool live = true; int batch = 0; };
    std::vector<Q> queries;
    int batch = 0, issued = 0, released = 0, waits = 0;
    bool inBatch = false;
    std::vector<std::vector<QueryVolume>> batches;

    void beginFrame(const Camera&, int, int) override {}
    void beginBatch() override { EXPECT_FALSE(inBatch); inBatch = true; batches.emplace_back(); }
    QueryId issue(const QueryVolume& v) override {
        EXPECT_TRUE(inBatch);
        queries.push_back({v, 0, true, batch});
        batches.back().push_back(v);
        ++issued;
        return static_cast<QueryId>(queries.size() - 1);
    }
    void endBatch() override { EXPECT_TRUE(inBatch); inBatch = false; ++batch; }
    QueryResult poll(QueryId id) override {
        Q& q = queries[id];
        EXPECT_TRUE(q.live);
        if (neverAnswer || q.polls++ < latency) return QueryResult::NotReady;
        return rule(q.v);
    }
    QueryResult wait(QueryId id, double) override {
        ++waits;
        if (neverAnswer) return QueryResult::NotReady;
        return rule(queries[id].v);
    }
    void release(QueryId id) override {
        EXPECT_TRUE(queries[id].live);
        queries[id].live = false;
        ++released;
    }
};

std::multiset<std::uint32_t> drawnWith(TestScene& s, SchedulerParams p, ScriptedBackend& backend, FrameStats* out = nullptr) {
    QueryScheduler sched(p);
    RecordingSink sink;
    TwoLevelTree tree(s.bsp, s.objects);
    FrameStats st = sched.cullFrame(tree, frontCamera(), 640, 320, backend, sink);
    if (out) *out = st;
    return sink.drawn;
}

}  // namespace

TEST(QueryScheduler, AllVisibleDrawsExactlyWhatVfcDraws) {
    TestScene s(6, 5);
    ScriptedBackend vfcBackend;
    SchedulerParams vfc;
    vfc.mode = CullMode::Vfc;
    const auto reference = drawnWith(s, vfc, vfcBackend);
    EXPECT_EQ(vfcBackend.issued, 0);
    EXPECT_FALSE(reference.empty());

    for (CullMode mode : {CullMode::Simple, CullMode::Full}) {
        for (int latency : {0, 3}) {
            ScriptedBackend b;
            b.latency = latency;
            SchedulerParams p;
            p.mode = mode;
            p.useOccupancyAccept = false;  // force queries
            FrameStats st;
            const auto drawn = drawnWith(s, p, b, &st);
            EXPECT_EQ(drawn, reference) << toString(mode) << " latency " << latency;
            EXPECT_GT(b.issued, 0);
            EXPECT_EQ(b.issued, b.released);  // every query returned to the pool
            EXPECT_EQ(st.queriesIssued, static_cast<std::uint32_t>(b.issued));
        }
    }
}

TEST(QueryScheduler, QueriesThatNeverAnswerCountAsVisibleAndTheFrameEnds) {
    TestScene s(4, 4);
    ScriptedBackend vfcBackend;
    SchedulerParams vfc;
    vfc.mode = CullMode::Vfc;
    const auto reference = drawnWith(s, vfc, vfcBackend);
    ScriptedBackend b;
    b.neverAnswer = true;
    SchedulerParams p;
    p.useOccupancyAccept = false;
    p.queryTimeoutMs = 1.0;
    FrameStats st;
    const auto drawn = drawnWith(s, p, b, &st);
    EXPECT_EQ(drawn, reference);
    EXPECT_GT(st.queriesTimedOut, 0u);
    EXPECT_EQ(st.queriesTimedOut, st.queriesIssued);
    EXPECT_EQ(b.issued, b.released);
}

TEST(QueryScheduler, OccludedAnswersCullButNeverNearOrInsideBoxes) {
    TestScene s(3, 3);
    // A cube around the camera: its box contains the eye and crosses the near plane.
    Transform t;
    t.translation = {0.0f, 0.0f, 0.0f};
    const ObjectHandle around = s.objects.addObject(0, t).take();
    s.bsp.update(s.objects);
    ScriptedBackend b;
    b.rule = [](const QueryVolume&) { return QueryResult::Occluded; };
    for (CullMode mode : {CullMode::Simple, CullMode::Full}) {
        SchedulerParams p;
        p.mode = mode;
        p.useOccupancyAccept = false;
        FrameStats st;
        const auto drawn = drawnWith(s, p, b, &st);
        EXPECT_EQ(drawn.count(around.index), 1u) << toString(mode);
        EXPECT_GT(st.visibleNearOrInside, 0u);
        EXPECT_GT(st.queriesOccluded, 0u);
    }
}

TEST(QueryScheduler, OccupancyAcceptNeedsNoQueryOnAnEmptyScreen) {
    TestScene s(1, 1);
    ScriptedBackend b;
    SchedulerParams p;
    FrameStats st;
    const auto drawn = drawnWith(s, p, b, &st);
    EXPECT_EQ(drawn.size(), 1u);
    EXPECT_EQ(b.issued, 0);
    EXPECT_GT(st.skippedByOccupancy, 0u);
}

TEST(QueryScheduler, HistorySkipsQueriesForNodesVisibleRecently) {
    TestScene s(5, 4);
    ScriptedBackend b;
    SchedulerParams p;
    p.useOccupancyAccept = false;
    QueryScheduler sched(p);
    TwoLevelTree tree(s.bsp, s.objects);
    std::vector<std::uint32_t> issued;
    std::uint32_t skipped = 0;
    for (int f = 0; f < 12; ++f) {
        RecordingSink sink;
        const FrameStats st = sched.cullFrame(tree, frontCamera(), 640, 320, b, sink);
        issued.push_back(st.queriesIssued);
        skipped += st.skippedByHistory;
    }
    EXPECT_GT(skipped, 0u);
    EXPECT_LT(*std::min_element(issued.begin() + 2, issued.end()), issued[0]);

    // Without history every frame issues the same number of queries.
    p.useHistory = false;
    QueryScheduler plain(p);
    std::set<std::uint32_t> counts;
    for (int f = 0; f < 5; ++f) {
        RecordingSink sink;
        counts.insert(plain.cullFrame(tree, frontCamera(), 640, 320, b, sink).queriesIssued);
    }
    EXPECT_EQ(counts.size(), 1u);
}

TEST(QueryScheduler, OccludedNodesAreQueriedAgainEveryFrame) {
    TestScene s(3, 3);
    ScriptedBackend b;
    b.rule = [](const QueryVolume&) { return QueryResult::Occluded; };
    SchedulerParams p;
    p.useOccupancyAccept = false;
    QueryScheduler sched(p);
    TwoLevelTree tree(s.bsp, s.objects);
    std::uint32_t first = 0;
    for (int f = 0; f < 6; ++f) {
        RecordingSink sink;
        const FrameStats st = sched.cullFrame(tree, frontCamera(), 640, 320, b, sink);
        if (f == 0) first = st.queriesIssued;
        EXPECT_EQ(st.queriesIssued, first);
        EXPECT_EQ(st.skippedByHistory, 0u);
    }
}

TEST(QueryScheduler, BatchesHoldOnlyNonOverlappingRectangles) {
    TestScene s(6, 6);
    ScriptedBackend b;
    b.latency = 2;
    SchedulerParams p;
    p.useOccupancyAccept = false;
    p.occupancyTileSize = 8;
    const Camera cam = frontCamera();
    const glm::mat4 vp = cam.viewProjection();
    drawnWith(s, p, b);
    // Rectangles of queries in flight together must not share a tile; queries issued in
    // one batch are in flight together.
    auto tilesOf = [&](const QueryVolume& v) {
        glm::vec2 lo(1e9f), hi(-1e9f);
        for (const glm::vec3& c : v.corners) {
            const glm::vec4 cl = vp * glm::vec4(c, 1.0f);
            const glm::vec2 px = (glm::vec2(cl) / cl.w + 1.0f) * 0.5f * glm::vec2(640, 320);
            lo = glm::min(lo, px);
            hi = glm::max(hi, px);
        }
        return std::pair(lo, hi);
    };
    int multi = 0;
    for (const auto& batch : b.batches) {
        if (batch.size() > 1) ++multi;
        for (std::size_t i = 0; i < batch.size(); ++i)
            for (std::size_t j = i + 1; j < batch.size(); ++j) {
                const auto [lo1, hi1] = tilesOf(batch[i]);
                const auto [lo2, hi2] = tilesOf(batch[j]);
                const bool overlap = lo1.x < hi2.x && lo2.x < hi1.x && lo1.y < hi2.y && lo2.y < hi1.y;
                EXPECT_FALSE(overlap) << "batch queries " << i << " and " << j << " overlap";
            }
    }
    EXPECT_GT(multi, 0) << "expected some batches with several queries";
}

TEST(QueryScheduler, ParamsAreValidated) {
    SchedulerParams p;
    EXPECT_TRUE(validateSchedulerParams(p).ok());
    p.maxQueriesInFlight = 0;
    EXPECT_FALSE(validateSchedulerParams(p).ok());
    p = {};
    p.occupancyTileSize = 0;
    EXPECT_FALSE(validateSchedulerParams(p).ok());
    EXPECT_FALSE(parseCullMode("fast").ok());
    EXPECT_EQ(parseCullMode("full").value(), CullMode::Full);
}

TEST(QueryScheduler, FrontMostLeavesAreDrawnWithoutQueries) {
    // k-DOP paper, section 4: the first frontPercent of the frustum leaves in front-to-back
    // order are drawn untested. Every query answers "occluded", so what is drawn is exactly
    // the front budget; at 100% everything in the frustum is drawn with no query at all.
    TestScene s(6, 5);
    ScriptedBackend vfcBackend;
    SchedulerParams vfc;
    vfc.mode = CullMode::Vfc;
    const auto reference = drawnWith(s, vfc, vfcBackend);
    ASSERT_EQ(reference.size(), 30u);
    std::uint32_t nearest = 0;
    float nearestDist = 1e30f;
    for (std::uint32_t o : reference) {
        const float d = glm::length(s.objects.worldBox(o).center());
        if (d < nearestDist) {
            nearestDist = d;
            nearest = o;
        }
    }
    for (CullMode mode : {CullMode::Simple, CullMode::Full}) {
        for (float percent : {10.0f, 50.0f, 100.0f}) {
            ScriptedBackend b;
            b.rule = [](const QueryVolume&) { return QueryResult::Occluded; };
            SchedulerParams p;
            p.mode = mode;
            p.useOccupancyAccept = false;
            p.frontPercent = percent;
            FrameStats st;
            const auto drawn = drawnWith(s, p, b, &st);
            const auto budget = static_cast<std::size_t>(std::ceil(percent / 100.0f * 30.0f));
            EXPECT_EQ(drawn.size(), budget) << toString(mode) << " " << percent;
            EXPECT_EQ(drawn.count(nearest), 1u) << toString(mode) << " " << percent;
            for (std::uint32_t o : drawn) EXPECT_EQ(reference.count(o), 1u);
            EXPECT_GE(st.visibleFront, budget);
            if (percent == 100.0f) {
                EXPECT_EQ(b.issued, 0);
            }
        }
    }
    SchedulerParams bad;
    bad.frontPercent = 150.0f;
    EXPECT_FALSE(validateSchedulerParams(bad));
}
