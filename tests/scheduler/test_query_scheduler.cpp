// Scheduler state-machine tests with scripted backends (no GL): latency, timeouts,
// conservative handling of near-plane boxes, history skipping and batching rules.
// Image-level correctness against vfc is tested with real GL in tests/engine.
#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <chrono>
#include <cmath>
#include <functional>
#include <map>
#include <set>
#include <string>
#include <thread>
#include <tuple>

#include "dyncull/bsp/local_bsp.hpp"
#include "dyncull/bsp/loose_bsp.hpp"
#include "dyncull/bsp/scene_objects.hpp"
#include "dyncull/bsp/traversal.hpp"
#include "dyncull/scheduler/query_scheduler.hpp"
#include "objects/sphere_grid.hpp"
#include "screen_projection.hpp"

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

/// The hardware-query mode these tests exercise (the library's default is two-phase).
SchedulerParams queriesParams() {
    SchedulerParams p;
    p.mode = CullMode::Queries;
    return p;
}

struct RecordingSink final : PartSink {
    std::multiset<std::uint32_t> drawn;
    std::vector<NodeRef> order;  ///< the parts in the order they were drawn
    void drawPart(NodeRef part, std::uint32_t, std::uint32_t) override {
        drawn.insert(part.object);
        order.push_back(part);
    }
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

    void beginFrame(const FrameView&) override {}
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

/// What frustum culling alone draws: the reference every conservative mode must match.
std::multiset<std::uint32_t> vfcDrawn(TestScene& s) {
    ScriptedBackend backend;
    SchedulerParams vfc;
    vfc.mode = CullMode::Vfc;
    auto drawn = drawnWith(s, vfc, backend);
    EXPECT_EQ(backend.issued, 0);  // vfc never queries
    return drawn;
}

}  // namespace

TEST(QueryScheduler, AllVisibleDrawsExactlyWhatVfcDraws) {
    TestScene s(6, 5);
    const auto reference = vfcDrawn(s);
    EXPECT_FALSE(reference.empty());

    for (CullMode mode : {CullMode::Simple, CullMode::Queries}) {
        for (int latency : {0, 3}) {
            ScriptedBackend b;
            b.latency = latency;
            SchedulerParams p = queriesParams();
            p.mode = mode;
            p.features.useOccupancyAccept = false;  // force queries
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
    const auto reference = vfcDrawn(s);
    ScriptedBackend b;
    b.neverAnswer = true;
    SchedulerParams p = queriesParams();
    p.features.useOccupancyAccept = false;
    p.tuning.queryTimeoutMs = 1.0;
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
    for (CullMode mode : {CullMode::Simple, CullMode::Queries}) {
        SchedulerParams p = queriesParams();
        p.mode = mode;
        p.features.useOccupancyAccept = false;
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
    SchedulerParams p = queriesParams();
    FrameStats st;
    const auto drawn = drawnWith(s, p, b, &st);
    EXPECT_EQ(drawn.size(), 1u);
    EXPECT_EQ(b.issued, 0);
    EXPECT_GT(st.skippedByOccupancy, 0u);
}

TEST(QueryScheduler, HistorySkipsQueriesForNodesVisibleRecently) {
    TestScene s(5, 4);
    ScriptedBackend b;
    SchedulerParams p = queriesParams();
    p.features.useOccupancyAccept = false;
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
    p.features.useHistory = false;
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
    SchedulerParams p = queriesParams();
    p.features.useOccupancyAccept = false;
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

// What the streamed read-ahead asks the culler: which nodes last frame reached, tested
// and found hidden. Drawn nodes and nodes never reached say no; so does a reused slot.
TEST(QueryScheduler, TestedHiddenLastFrameNamesExactlyTheNodesAQueryHid) {
    TestScene s(3, 3);
    ScriptedBackend b;
    // Object-sized volumes right of centre are hidden; scene nodes (larger) never are.
    b.rule = [](const QueryVolume& v) {
        Aabb box;
        for (const glm::vec3& p : v.points()) box.extend(p);
        const glm::vec3 size = box.max - box.min;
        return std::max({size.x, size.y, size.z}) < 0.9f && box.center().x > 0.5f ? QueryResult::Occluded
                                                                                   : QueryResult::Visible;
    };
    SchedulerParams p = queriesParams();
    p.features.useOccupancyAccept = false;
    QueryScheduler sched(p);
    TwoLevelTree tree(s.bsp, s.objects);
    RecordingSink sink;
    for (const ObjectHandle h : s.handles) EXPECT_FALSE(sched.testedHiddenLastFrame(NodeRef{h.index, 0}, s.objects));
    sched.cullFrame(tree, frontCamera(), 640, 320, b, sink);
    std::size_t hidden = 0;
    for (const ObjectHandle h : s.handles) {
        const bool right = s.objects.worldBox(h.index).center().x > 0.5f;
        const bool testedHidden = sched.testedHiddenLastFrame(NodeRef{h.index, 0}, s.objects);
        EXPECT_EQ(testedHidden, right && sink.drawn.count(h.index) == 0) << h.index;
        EXPECT_EQ(sink.drawn.count(h.index) == 0, right) << h.index;
        hidden += testedHidden;
    }
    EXPECT_EQ(hidden, 3u);
    // A slot reused by a new object has no history of the old one.
    const ObjectHandle gone = s.handles.back();
    const Transform where = s.objects.transform(gone.index);
    ASSERT_TRUE(s.objects.removeObject(gone).ok());
    const ObjectHandle reused = s.objects.addObject(s.objects.modelOf(s.handles.front().index), where).take();
    ASSERT_EQ(reused.index, gone.index);
    EXPECT_FALSE(sched.testedHiddenLastFrame(NodeRef{reused.index, 0}, s.objects));
}

TEST(QueryScheduler, BatchesHoldOnlyNonOverlappingRectangles) {
    TestScene s(6, 6);
    ScriptedBackend b;
    b.latency = 2;
    SchedulerParams p = queriesParams();
    p.features.useOccupancyAccept = false;
    p.tuning.occupancyTileSize = 8;
    const Camera cam = frontCamera();
    const glm::mat4 vp = cam.viewProjection();
    drawnWith(s, p, b);
    // Rectangles of queries in flight together must not share a tile; queries issued in
    // one batch are in flight together.
    auto tilesOf = [&](const QueryVolume& v) {
        glm::vec2 lo(1e9f), hi(-1e9f);
        for (const glm::vec3& c : v.points()) {
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

TEST(QueryScheduler, WithWaitOrderAFartherNodeNeverOvertakesAWaitingNearerNodeItOverlaps) {
    // Three cubes seen from the origin: P nearest; A behind, overlapping P on screen (so A
    // waits for P's query); F farthest, overlapping A but not P. F must wait for A too:
    // queried before A's answer, F would be tested against a depth buffer still missing A.
    SceneObjects objects;
    const ModelId cube = objects.addModel(cubeModel(0.4f));
    const glm::vec3 at[3] = {{0.0f, 0.0f, -3.0f}, {1.0f, 0.0f, -5.0f}, {2.0f, 0.0f, -7.0f}};
    for (const glm::vec3& p : at) {
        Transform t;
        t.translation = p;
        ASSERT_TRUE(objects.addObject(cube, t).ok());
    }
    LooseBsp bsp;
    bsp.build(objects);
    ScriptedBackend b;
    b.latency = 2;
    SchedulerParams p = queriesParams();
    p.features.useOccupancyAccept = false;  // an empty screen would accept everything
    p.tuning.occupancyTileSize = 8;
    p.features.useWaitOrder = true;
    QueryScheduler sched(p);
    RecordingSink sink;
    TwoLevelTree tree(bsp, objects);
    sched.cullFrame(tree, frontCamera(), 640, 320, b, sink);
    EXPECT_EQ(sink.drawn.size(), 3u);
    // Issue order of the three cube queries (the scene root's box is larger).
    std::vector<int> order;
    for (const auto& q : b.queries) {
        glm::vec3 c(0.0f);
        for (const glm::vec3& v : q.v.points()) c += v / 8.0f;
        for (int i = 0; i < 3; ++i)
            if (glm::length(c - at[i]) < 1e-3f && std::abs(q.v.points()[7].x - q.v.points()[0].x - 0.8f) < 1e-3f)
                order.push_back(i);
    }
    ASSERT_EQ(order.size(), 3u);
    EXPECT_EQ(order, (std::vector<int>{0, 1, 2}));
}

TEST(QueryScheduler, ParamsAreValidated) {
    SchedulerParams p = queriesParams();
    EXPECT_TRUE(validateSchedulerParams(p).ok());
    p.tuning.maxQueriesInFlight = 0;
    EXPECT_FALSE(validateSchedulerParams(p).ok());
    p = {};
    p.tuning.occupancyTileSize = 0;
    EXPECT_FALSE(validateSchedulerParams(p).ok());
    for (const int span : {0, 1, 65}) {
        p = {};
        p.tuning.pyramidSpan = span;
        EXPECT_FALSE(validateSchedulerParams(p).ok()) << span;
        p = {};
        p.tuning.clusterPyramidSpan = span;
        EXPECT_FALSE(validateSchedulerParams(p).ok()) << span;
        p = {};
        p.tuning.recordPyramidSpan = span;
        EXPECT_FALSE(validateSchedulerParams(p).ok()) << span;
    }
    for (const int texels : {-1, 65537}) {
        p = {};
        p.tuning.texelTestTexels = texels;
        EXPECT_FALSE(validateSchedulerParams(p).ok()) << texels;
        p = {};
        p.tuning.clusterTexelTests = texels;
        EXPECT_FALSE(validateSchedulerParams(p).ok()) << texels;
    }
    for (const std::uint32_t rounds : {0u, 17u}) {
        p = {};
        p.tuning.candidateRounds = rounds;
        EXPECT_FALSE(validateSchedulerParams(p).ok()) << rounds;
    }
    p = {};
    p.tuning.candidateRounds = 16;
    p.tuning.pyramidSpan = 64;
    p.tuning.clusterPyramidSpan = 2;
    p.tuning.recordPyramidSpan = 64;
    p.tuning.texelTestTexels = 0;
    p.tuning.clusterTexelTests = 65536;
    EXPECT_TRUE(validateSchedulerParams(p).ok());
    EXPECT_FALSE(parseCullMode("fast").ok());
    EXPECT_EQ(parseCullMode("full").value(), CullMode::TwoPhase);
    EXPECT_EQ(parseCullMode("queries").value(), CullMode::Queries);
    for (CullMode m : {CullMode::Vfc, CullMode::Simple, CullMode::Queries, CullMode::TwoPhase})
        EXPECT_EQ(parseCullMode(toString(m)).value(), m);
}

// Which of `cubes` (front-face distances from the eye along -Z, cube half size `half`)
// full mode draws when every query answers "occluded": only boxes it must not query
// (crossing the near plane, within rounding of it) get drawn.
std::vector<bool> drawnWhenAllOccluded(const glm::vec3& eye, float nearPlane, float farPlane, float half,
                                       const std::vector<double>& frontDistances, FrameStats& st) {
    SceneObjects objects;
    const ModelId cube = objects.addModel(cubeModel(half));
    std::vector<ObjectHandle> hs;
    for (std::size_t i = 0; i < frontDistances.size(); ++i) {
        Transform t;  // side by side, all inside the view
        t.translation = glm::vec3(glm::dvec3(eye) + glm::dvec3((double(i) - 0.5 * double(frontDistances.size() - 1)) * 3.0 * half, 0.0,
                                                               -(frontDistances[i] + half)));
        hs.push_back(objects.addObject(cube, t).take());
    }
    LooseBsp bsp;
    bsp.build(objects);
    Camera c;
    c.position = eye;
    c.target = eye + glm::vec3(0, 0, -1);
    c.nearPlane = nearPlane;
    c.farPlane = farPlane;
    c.aspect = 2.0f;
    ScriptedBackend b;
    b.rule = [](const QueryVolume&) { return QueryResult::Occluded; };
    SchedulerParams p = queriesParams();
    p.features.useOccupancyAccept = false;
    QueryScheduler sched(p);
    RecordingSink sink;
    TwoLevelTree tree(bsp, objects);
    st = sched.cullFrame(tree, c, 640, 320, b, sink);
    std::vector<bool> drawn;
    for (const ObjectHandle& h : hs) drawn.push_back(sink.drawn.count(h.index) > 0);
    return drawn;
}

TEST(QueryScheduler, NearPlaneTestHoldsAtNear1eMinus4AndFar1e7) {
    // Cubes of half size 1e-5 whose front faces are 1e-6 of the near distance behind the
    // near plane (crossing it by 1e-10 units: drawn without a query) and 1e-3 in front
    // (queried, answered occluded, not drawn).
    const double n = 1e-4;
    FrameStats st;
    const auto drawn = drawnWhenAllOccluded({0, 0, 0}, float(n), 1e7f, 1e-5f, {n * (1.0 - 1e-6), n * (1.0 + 1e-3)}, st);
    EXPECT_TRUE(drawn[0]);
    EXPECT_FALSE(drawn[1]);
    EXPECT_GE(st.visibleNearOrInside, 1u);
    EXPECT_GE(st.queriesOccluded, 1u);
}

TEST(QueryScheduler, BoxesWithinWorldRoundingOfTheNearPlaneAreNotQueried) {
    // Eye 1e6 units from the origin, where world coordinates round to 2^-4 units and query
    // volumes may be padded by 2^-22 of them (0.24 units): a cube 0.2 in front of the eye
    // is drawn without a query (its volume could reach the near plane), one 20 in front is
    // queried (occluded, not drawn).
    FrameStats st;
    const auto drawn = drawnWhenAllOccluded({1e6f, 0, 0}, 0.01f, 1e4f, 0.05f, {0.2, 20.0}, st);
    EXPECT_TRUE(drawn[0]);
    EXPECT_FALSE(drawn[1]);
}

TEST(QueryScheduler, FrontMostLeavesAreDrawnWithoutQueries) {
    // k-DOP paper, section 4: the first frontPercent of the frustum leaves in front-to-back
    // order are drawn untested. Every query answers "occluded", so what is drawn is exactly
    // the front budget; at 100% everything in the frustum is drawn with no query at all.
    TestScene s(6, 5);
    const auto reference = vfcDrawn(s);
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
    for (CullMode mode : {CullMode::Simple, CullMode::Queries}) {
        for (float percent : {10.0f, 50.0f, 100.0f}) {
            ScriptedBackend b;
            b.rule = [](const QueryVolume&) { return QueryResult::Occluded; };
            SchedulerParams p = queriesParams();
            p.mode = mode;
            p.features.useOccupancyAccept = false;
            p.tuning.frontPercent = percent;
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
    bad.tuning.frontPercent = 150.0f;
    EXPECT_FALSE(validateSchedulerParams(bad));
}

namespace {

// A rotated lumpy sphere split into a few parts, instanced on a grid in front of the camera.
Mesh lumpySphere() {
    Mesh m;
    const int slices = 40, stacks = 24;
    for (int j = 0; j <= stacks; ++j) {
        const float phi = 3.14159265f * float(j) / float(stacks);
        for (int i = 0; i < slices; ++i) {
            const float th = 6.2831853f * float(i) / float(slices);
            const float r = 0.4f * (1.0f + 0.2f * std::sin(3.0f * phi) * std::cos(4.0f * th));
            m.positions.push_back(r * glm::vec3(std::sin(phi) * std::cos(th), 0.7f * std::cos(phi), std::sin(phi) * std::sin(th)));
        }
    }
    test::appendSphereGridTriangles(m, slices, stacks);
    return m;
}

}  // namespace

TEST(QueryScheduler, ObjectNodesAreQueriedWithTheChosenVolume) {
    SceneObjects objects;
    LocalBspParams lp;
    lp.maxLeafTriangles = 400;
    const ModelId model = objects.addModel(buildLocalBsp(lumpySphere(), lp).take());
    ASSERT_GT(objects.model(model).nodes.size(), 3u);
    for (int i = 0; i < 12; ++i) {
        Transform t;
        t.translation = {float(i % 4) - 1.5f, float(i / 4) - 1.0f, -4.0f - 0.5f * float(i)};
        t.rotation = glm::angleAxis(0.3f * float(i), glm::normalize(glm::vec3(1, 2, 0.5f)));
        t.scale = {1.0f + 0.1f * float(i % 3), 0.8f, 1.2f};
        objects.addObject(model, t).take();
    }
    LooseBsp bsp;
    bsp.build(objects);
    TwoLevelTree tree(bsp, objects);
    for (VolumeChoice c : {VolumeChoice::Aabb, VolumeChoice::Obb, VolumeChoice::Kdop14, VolumeChoice::Kdop18,
                           VolumeChoice::Kdop26, VolumeChoice::Auto}) {
        SCOPED_TRACE(toString(c));
        ScriptedBackend b;
        SchedulerParams p = queriesParams();
        p.features.useOccupancyAccept = false;  // force queries
        p.features.useHistory = false;
        p.tuning.volume = c;
        QueryScheduler sched(p);
        RecordingSink sink;
        const FrameStats st = sched.cullFrame(tree, frontCamera(), 640, 320, b, sink);
        std::uint64_t triangles = 0;
        std::uint32_t meshes = 0, boxes = 0;
        for (const auto& q : b.queries) {
            triangles += q.v.isBox() ? 12u : q.v.triangleCount;
            (q.v.isBox() ? boxes : meshes) += 1;
            EXPECT_LE(q.v.triangleCount, QueryVolume::kMaxTriangles);
            EXPECT_EQ(q.v.isBox() ? 8u : q.v.triangles().size() / 3, q.v.isBox() ? q.v.vertexCount : q.v.triangleCount);
        }
        EXPECT_EQ(st.queryTriangles, triangles);
        EXPECT_GT(boxes, 0u);  // scene nodes are always world boxes
        if (c == VolumeChoice::Aabb || c == VolumeChoice::Obb) EXPECT_EQ(meshes, 0u);
        else EXPECT_GT(meshes, 0u);
    }
    // Simple and the untightened ablation query world boxes only.
    for (bool simple : {true, false}) {
        ScriptedBackend b;
        SchedulerParams p = queriesParams();
        p.mode = simple ? CullMode::Simple : CullMode::Queries;
        p.features.useTightVolumes = simple;
        p.features.useOccupancyAccept = false;
        p.tuning.volume = VolumeChoice::Kdop26;
        QueryScheduler sched(p);
        RecordingSink sink;
        sched.cullFrame(tree, frontCamera(), 640, 320, b, sink);
        EXPECT_GT(b.queries.size(), 0u);
        for (const auto& q : b.queries) EXPECT_TRUE(q.v.isBox());
    }
}

TEST(QueryVolume, NodeVolumesAreTransformedVertexByVertex) {
    LocalBspParams lp;
    lp.maxLeafTriangles = 400;
    const LocalBsp bsp = buildLocalBsp(lumpySphere(), lp).take();
    Transform t;
    t.translation = {3, -1, 2};
    t.rotation = glm::angleAxis(1.0f, glm::normalize(glm::vec3(0.2f, 1, -0.4f)));
    t.scale = {2.0f, 0.5f, 1.0f};
    const glm::mat4 m = t.matrix();
    for (std::uint32_t n = 0; n < bsp.nodes.size(); ++n)
        for (VolumeKind k : {VolumeKind::Aabb, VolumeKind::Obb, VolumeKind::Kdop14, VolumeKind::Kdop18, VolumeKind::Kdop26}) {
            const NodeVolume& e = bsp.volumes.get(n, k);
            const QueryVolume q = QueryVolume::fromNodeVolume(m, bsp.volumes, e);
            ASSERT_EQ(q.vertexCount, e.vertexCount);
            ASSERT_EQ(q.isBox(), e.isBox());
            const auto src = bsp.volumes.verticesOf(e);
            for (std::uint32_t i = 0; i < q.vertexCount; ++i) EXPECT_EQ(q.vertices[i], glm::vec3(m * glm::vec4(src[i], 1.0f)));
            const auto tri = q.triangles();
            if (e.isBox()) EXPECT_EQ(tri.size(), 36u);
            else EXPECT_TRUE(std::equal(tri.begin(), tri.end(), bsp.volumes.indicesOf(e).begin()));
        }
    // The AABB kind is exactly the tightened local box of before.
    const QueryVolume a = QueryVolume::fromNodeVolume(m, bsp.volumes, bsp.volumes.get(0, VolumeKind::Aabb));
    const QueryVolume b = QueryVolume::fromTransformedBox(m, bsp.nodes[0].box);
    for (int i = 0; i < 8; ++i) EXPECT_EQ(a.vertices[i], b.vertices[i]);
}

// objectNodeVolumeKind and objectNodeBox say what objectNodeVolume builds: wherever the kind
// is Aabb, its vertices are those of objectNodeBox under the object's matrix (the two-phase
// pyramid test projects that box without building the volume), for every choice of volume.
TEST(QueryVolume, ObjectNodeBoxIsTheBoxObjectNodeVolumeTransforms) {
    LocalBspParams lp;
    lp.maxLeafTriangles = 400;
    SceneObjects objs;
    const ModelId model = objs.addModel(buildLocalBsp(lumpySphere(), lp).take());
    Transform t;
    t.translation = {3, -1, 2};
    t.rotation = glm::angleAxis(1.0f, glm::normalize(glm::vec3(0.2f, 1, -0.4f)));
    t.scale = {2.0f, 0.5f, 1.0f};
    const ObjectHandle h = objs.addObject(model, t).take();
    const glm::mat4& m = objs.matrix(h.index);
    int boxes = 0;
    for (const VolumeChoice choice : {VolumeChoice::Aabb, VolumeChoice::Obb, VolumeChoice::Auto})
        for (const float saving : {0.0f, 0.1f, 1.0f})
            for (std::uint32_t n = 0; n < objs.model(model).nodes.size(); ++n) {
                const NodeRef ref{h.index, n};
                if (objectNodeVolumeKind(objs, ref, choice, saving) != VolumeKind::Aabb) continue;
                const QueryVolume v = objectNodeVolume(objs, ref, choice, saving);
                const QueryVolume b = QueryVolume::fromTransformedBox(m, objectNodeBox(objs, ref, choice));
                ASSERT_EQ(v.vertexCount, 8u);
                std::vector<glm::vec3> a(v.points().begin(), v.points().end()), c(b.points().begin(), b.points().end());
                auto less = [](const glm::vec3& x, const glm::vec3& y) { return std::tie(x.x, x.y, x.z) < std::tie(y.x, y.y, y.z); };
                std::sort(a.begin(), a.end(), less);
                std::sort(c.begin(), c.end(), less);
                EXPECT_EQ(a, c) << "node " << n;
                ++boxes;
            }
    EXPECT_GT(boxes, 0);
}

// ---- Draw queries: parts drawn without a query of their own are drawn inside a query
// on their geometry; its answer decides the part's next frame.

namespace {

// Box queries as ScriptedBackend (always visible, answered at once); draw queries
// answered per object by `drawRule` (NotReady: never answers), the object being the one
// the sink drew inside the query.
struct DrawQueryBackend final : QueryBackend {
    static constexpr QueryId kDrawBase = 1u << 20;
    std::function<QueryResult(std::uint32_t object)> drawRule = [](std::uint32_t) { return QueryResult::Visible; };
    std::vector<std::uint32_t> drawObject;  // per draw query: object drawn inside it
    std::vector<bool> live;                 // per draw query
    std::vector<QueryVolume> boxes;         // box queries of the current frame
    int boxIssued = 0, boxReleased = 0, drawReleased = 0;
    bool inDraw = false;
    std::uint32_t lastDrawn = ~0u;  // written by the sink

    void beginFrame(const FrameView&) override { boxes.clear(); }
    void beginBatch() override { EXPECT_FALSE(inDraw); }
    QueryId issue(const QueryVolume& v) override {
        boxes.push_back(v);
        return static_cast<QueryId>(boxIssued++);
    }
    void endBatch() override {}
    QueryResult poll(QueryId id) override {
        if (id < kDrawBase) return QueryResult::Visible;
        EXPECT_TRUE(live[id - kDrawBase]);
        return drawRule(drawObject[id - kDrawBase]);
    }
    QueryResult wait(QueryId id, double) override {
        const QueryResult r = poll(id);
        return r == QueryResult::NotReady ? QueryResult::NotReady : r;
    }
    void release(QueryId id) override {
        if (id < kDrawBase) {
            ++boxReleased;
            return;
        }
        EXPECT_TRUE(live[id - kDrawBase]);
        live[id - kDrawBase] = false;
        ++drawReleased;
    }
    QueryId beginDrawQuery() override {
        EXPECT_FALSE(inDraw);
        inDraw = true;
        lastDrawn = ~0u;
        drawObject.push_back(~0u);
        live.push_back(true);
        return kDrawBase + static_cast<QueryId>(drawObject.size() - 1);
    }
    void endDrawQuery(QueryId id) override {
        EXPECT_TRUE(inDraw);
        inDraw = false;
        drawObject[id - kDrawBase] = lastDrawn;
    }
    /// Box queries this frame on a volume centred at x (the cubes of TestScene(3, 1) sit
    /// at x = -1, 0, 1; larger scene-node boxes are not counted).
    int objectQueriesAt(float x) const {
        int n = 0;
        for (const QueryVolume& v : boxes) {
            Aabb b;
            for (const glm::vec3& q : v.points()) b.extend(q);
            if (b.extent().x < 1.0f && std::abs(b.center().x - x) < 1e-3f) ++n;
        }
        return n;
    }
};

struct ForwardingSink final : PartSink {
    DrawQueryBackend& backend;
    std::multiset<std::uint32_t> drawn;
    explicit ForwardingSink(DrawQueryBackend& b) : backend(b) {}
    void drawPart(NodeRef part, std::uint32_t, std::uint32_t) override {
        drawn.insert(part.object);
        backend.lastDrawn = part.object;
    }
};

}  // namespace

TEST(QueryScheduler, DrawQueriesKeepVisiblePartsUnqueriedAndRequeryPartsThatDrewNothing) {
    TestScene s(3, 1);
    const auto reference = vfcDrawn(s);
    ASSERT_EQ(reference.size(), 3u);
    for (bool drawQueries : {true, false}) {
        SCOPED_TRACE(drawQueries ? "draw queries" : "history only");
        DrawQueryBackend b;
        SchedulerParams p = queriesParams();
        p.features.useOccupancyAccept = false;  // every part needs a query or history
        p.tuning.history.jitter = false;
        p.features.useDrawQueries = drawQueries;
        QueryScheduler sched(p);
        TwoLevelTree tree(s.bsp, s.objects);
        auto frame = [&] {
            ForwardingSink sink(b);
            const FrameStats st = sched.cullFrame(tree, frontCamera(), 640, 320, b, sink);
            EXPECT_EQ(sink.drawn, reference);  // every box answers visible: nothing is culled
            return st;
        };
        // Every geometry visible: after two box answers a part is never box-queried again
        // with draw queries; history alone re-queries it within maxSkipFrames.
        int requeries = 0;
        for (int f = 0; f < 20; ++f) {
            const FrameStats st = frame();
            if (f < 3) continue;
            requeries += b.objectQueriesAt(-1.0f) + b.objectQueriesAt(0.0f) + b.objectQueriesAt(1.0f);
            EXPECT_EQ(st.drawQueries, drawQueries ? 3u : 0u);  // the three parts, skipped by history
        }
        if (drawQueries) {
            EXPECT_EQ(requeries, 0);
        } else {
            EXPECT_GT(requeries, 0);
        }

        // The left cube's geometry drew nothing last frame (answers are read at the start
        // of the next frame): with draw queries it is queried by box now, the others are
        // not; history alone skips it.
        b.drawRule = [](std::uint32_t object) { return object == 0 ? QueryResult::Occluded : QueryResult::Visible; };
        const FrameStats st = frame();
        b.drawRule = [](std::uint32_t) { return QueryResult::Visible; };
        EXPECT_EQ(b.objectQueriesAt(-1.0f), drawQueries ? 1 : 0);
        EXPECT_EQ(b.objectQueriesAt(0.0f) + b.objectQueriesAt(1.0f), 0);
        EXPECT_EQ(st.drawQueriesOccluded, drawQueries ? 1u : 0u);

        // Draw queries that never answer are dropped at the frame's end (history decides
        // as without them) and every one is released.
        b.drawRule = [](std::uint32_t) { return QueryResult::NotReady; };
        std::uint32_t late = 0;
        for (int f = 0; f < 12; ++f) late += frame().drawQueriesLate;
        if (drawQueries) {
            EXPECT_GT(late, 0u);
        }
        b.drawRule = [](std::uint32_t) { return QueryResult::Visible; };
        p.mode = CullMode::Vfc;  // leaving Full releases the last frame's draw queries
        sched.setParams(p);
        frame();
        EXPECT_EQ(b.drawReleased, static_cast<int>(b.drawObject.size()));
        EXPECT_EQ(b.boxReleased, b.boxIssued);
    }
}

// ---- Faults: a backend that never answers (lost or hung GPU). The contract of
// QueryBackend::wait is a bounded wait; the scheduler must then count the node visible
// (never cull on a missing answer) and end the frame.

namespace {

// Never answers: poll is always NotReady; wait really waits `timeoutMs` of wall time (as
// a GL backend polling a hung query would) and then gives up.
struct HungBackend final : QueryBackend {
    int issued = 0, released = 0, polls = 0, waits = 0;
    std::vector<double> waitBounds;
    void beginFrame(const FrameView&) override {}
    void beginBatch() override {}
    QueryId issue(const QueryVolume&) override { return static_cast<QueryId>(issued++); }
    void endBatch() override {}
    QueryResult poll(QueryId) override {
        ++polls;
        return QueryResult::NotReady;
    }
    QueryResult wait(QueryId, double timeoutMs) override {
        ++waits;
        waitBounds.push_back(timeoutMs);
        const auto until = std::chrono::steady_clock::now() + std::chrono::duration<double, std::milli>(timeoutMs);
        while (std::chrono::steady_clock::now() < until) std::this_thread::yield();
        return QueryResult::NotReady;
    }
    void release(QueryId) override { ++released; }
};

}  // namespace

TEST(QueryFaults, HungQueriesInTheWaitPathCountVisibleWithinTheBound) {
    // Simple OC: every query goes through wait().
    TestScene s(4, 3);
    const auto reference = vfcDrawn(s);
    HungBackend b;
    SchedulerParams p = queriesParams();
    p.mode = CullMode::Simple;
    p.tuning.queryTimeoutMs = 2.0;
    QueryScheduler sched(p);
    RecordingSink sink;
    TwoLevelTree tree(s.bsp, s.objects);
    const auto t0 = std::chrono::steady_clock::now();
    const FrameStats st = sched.cullFrame(tree, frontCamera(), 640, 320, b, sink);
    const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    EXPECT_EQ(sink.drawn, reference);  // nothing culled on a missing answer
    ASSERT_GT(b.issued, 0);
    EXPECT_EQ(st.queriesTimedOut, static_cast<std::uint32_t>(b.issued));
    EXPECT_EQ(b.waits, b.issued);
    for (double bound : b.waitBounds) EXPECT_EQ(bound, 2.0);
    EXPECT_EQ(b.released, b.issued);
    // Each wait is bounded: the frame costs about issued x 2 ms, not forever (generous
    // slack for a loaded machine).
    EXPECT_LT(ms, b.issued * 2.0 + 2000.0);
}

TEST(QueryFaults, HungQueriesInTheNonBlockingPathCountVisibleWithinTheBound) {
    // Full mode polls first and only waits when nothing else is left; with a small
    // in-flight limit it must go through both paths many times.
    TestScene s(5, 4);
    const auto reference = vfcDrawn(s);
    HungBackend b;
    SchedulerParams p = queriesParams();
    p.mode = CullMode::Queries;
    p.features.useOccupancyAccept = false;  // force queries
    p.features.useHistory = false;
    p.tuning.maxQueriesInFlight = 3;
    p.tuning.queryTimeoutMs = 1.0;
    QueryScheduler sched(p);
    RecordingSink sink;
    TwoLevelTree tree(s.bsp, s.objects);
    for (int frame = 0; frame < 3; ++frame) {
        sink.drawn.clear();
        const int issuedBefore = b.issued;
        const FrameStats st = sched.cullFrame(tree, frontCamera(), 640, 320, b, sink);
        EXPECT_EQ(sink.drawn, reference) << "frame " << frame;
        EXPECT_GT(st.queriesIssued, 0u);
        EXPECT_EQ(st.queriesTimedOut, st.queriesIssued);
        EXPECT_EQ(b.issued - issuedBefore, static_cast<int>(st.queriesIssued));
    }
    EXPECT_GT(b.polls, b.waits);  // the non-blocking path was taken before every wait
    EXPECT_EQ(b.waits, b.issued);  // and each query was waited for exactly once, bounded
    EXPECT_EQ(b.released, b.issued);
}

TEST(QueryFaults, HungQueriesWithLastFrameResultsNeverCullAndNeverPileUp) {
    // The approximate one-frame-latency setting never waits: unanswered queries stay
    // in flight, the node stays visible, and no second query is stacked on it.
    TestScene s(4, 3);
    const auto reference = vfcDrawn(s);
    HungBackend b;
    SchedulerParams p = queriesParams();
    p.features.useOccupancyAccept = false;
    p.features.useHistory = false;
    p.approx.useLastFrameResults = true;
    QueryScheduler sched(p);
    RecordingSink sink;
    TwoLevelTree tree(s.bsp, s.objects);
    int issuedAfterFirst = 0;
    for (int frame = 0; frame < 20; ++frame) {
        sink.drawn.clear();
        sched.cullFrame(tree, frontCamera(), 640, 320, b, sink);
        EXPECT_EQ(sink.drawn, reference) << "frame " << frame;
        if (frame == 0) issuedAfterFirst = b.issued;
    }
    EXPECT_GT(issuedAfterFirst, 0);
    EXPECT_EQ(b.issued, issuedAfterFirst);  // bounded: one query per node at most
    EXPECT_EQ(b.waits, 0);
}

TEST(QueryFaults, AnswersForARemovedObjectAreDroppedWhenItsSlotIsReused) {
    // Frame 1: spheres of a many-node model; with one-frame latency their queries are read
    // in frame 2. In between every sphere is removed and its slot reused by a one-node cube
    // in the same place. The late answers name the spheres' nodes: recorded for the cubes,
    // they would say "occluded" for a cube never queried (and name nodes it does not have).
    Mesh sphere;
    const int slices = 24, stacks = 16;
    for (int j = 0; j <= stacks; ++j)
        for (int i = 0; i < slices; ++i) {
            const float phi = 3.14159265f * float(j) / float(stacks), theta = 6.2831853f * float(i) / float(slices);
            sphere.positions.push_back(0.3f * glm::vec3(std::sin(phi) * std::cos(theta), std::cos(phi), std::sin(phi) * std::sin(theta)));
        }
    test::appendSphereGridTriangles(sphere, slices, stacks);
    LocalBspParams fine;
    fine.maxLeafTriangles = 40;
    auto sphereBsp = buildLocalBsp(sphere, fine);
    ASSERT_TRUE(sphereBsp.ok());
    ASSERT_GT(sphereBsp->nodes.size(), 8u);

    SceneObjects objects;
    const ModelId sphereModel = objects.addModel(sphereBsp.take());
    const ModelId cube = objects.addModel(cubeModel(0.4f));
    std::vector<Transform> places;
    std::vector<ObjectHandle> handles;
    for (int i = 0; i < 6; ++i) {
        Transform t;
        t.translation = {1.2f * static_cast<float>(i) - 3.0f, 0.0f, -4.0f};
        places.push_back(t);
        handles.push_back(objects.addObject(sphereModel, t).take());
    }
    LooseBsp bsp;
    bsp.build(objects);

    // The spheres' node volumes (at most 0.6 across) answer occluded; the loose-BSP cells
    // around them and the cubes (0.8) answer visible.
    ScriptedBackend b;
    b.rule = [](const QueryVolume& v) {
        glm::vec3 lo(1e30f), hi(-1e30f);
        for (std::uint32_t i = 0; i < v.vertexCount; ++i) {
            lo = glm::min(lo, v.vertices[i]);
            hi = glm::max(hi, v.vertices[i]);
        }
        const glm::vec3 e = hi - lo;
        return std::max({e.x, e.y, e.z}) < 0.65f ? QueryResult::Occluded : QueryResult::Visible;
    };
    SchedulerParams p = queriesParams();
    p.approx.useLastFrameResults = true;
    p.features.useHistory = false;
    p.features.useOccupancyAccept = false;
    p.features.useDrawQueries = false;
    QueryScheduler sched(p);
    RecordingSink sink;
    {
        TwoLevelTree tree(bsp, objects);
        sched.cullFrame(tree, frontCamera(), 640, 320, b, sink);
    }
    ASSERT_GT(b.issued, 6);

    for (const ObjectHandle h : handles) ASSERT_TRUE(objects.removeObject(h).ok());
    std::set<std::uint32_t> cubes;
    for (const Transform& t : places) {
        const ObjectHandle h = objects.addObject(cube, t).take();
        cubes.insert(h.index);
    }
    ASSERT_EQ(cubes.size(), 6u);
    for (const ObjectHandle h : handles) ASSERT_TRUE(cubes.count(h.index)) << "the test needs the slots reused";
    bsp.update(objects);

    sink.drawn.clear();
    {
        TwoLevelTree tree(bsp, objects);
        sched.cullFrame(tree, frontCamera(), 640, 320, b, sink);
    }
    // Every cube is new: nothing known about it, so it is drawn while its query is in flight.
    EXPECT_EQ(std::set<std::uint32_t>(sink.drawn.begin(), sink.drawn.end()), cubes);
}

namespace {

/// Two-phase's backend without GL: a depth buffer of one value everywhere (reversed Z: 0
/// is far, nothing occluded; 1 is the near plane, everything occluded) and batched raster
/// tests answered by `rule`. Counts depth reads and tested volumes.
struct DepthBackend final : QueryBackend {
    float depth = 0.0f;
    std::function<float(int, int)> depthAt;  // per pixel (x, y from the lower left) if set

    std::function<QueryResult(const QueryVolume&)> rule = [](const QueryVolume&) { return QueryResult::Visible; };
    int reads = 0, tested = 0, batches = 0, finishes = 0;
    std::vector<std::vector<QueryResult>> answers;  // per batch, until collected
    std::function<void()> onRead;  // called at each depth read, if set

    void finishDrawing() override { ++finishes; }

    void beginFrame(const FrameView&) override {}
    void beginBatch() override { ADD_FAILURE() << "two-phase issues no hardware query"; }
    QueryId issue(const QueryVolume&) override { return 0; }
    void endBatch() override {}
    QueryResult poll(QueryId) override { return QueryResult::Visible; }
    QueryResult wait(QueryId, double) override { return QueryResult::Visible; }
    void release(QueryId) override {}
    bool readDepth(std::vector<float>& d, int& w, int& h) override {
        ++reads;
        if (onRead) onRead();
        w = 640;
        h = 320;
        d.assign(std::size_t{640} * 320, depth);
        if (depthAt)
            for (int y = 0; y < h; ++y)
                for (int x = 0; x < w; ++x) d[std::size_t(y) * std::size_t(w) + std::size_t(x)] = depthAt(x, y);
        return true;
    }
    BatchId testVolumes(std::span<const QueryVolume> volumes, bool = false) override {
        tested += static_cast<int>(volumes.size());
        ++batches;
        answers.emplace_back();
        for (const QueryVolume& v : volumes) answers.back().push_back(rule(v));
        return static_cast<BatchId>(answers.size() - 1);
    }
    bool collectVolumes(BatchId id, std::span<QueryResult> out, double, std::span<std::uint32_t> samples = {}) override {
        EXPECT_EQ(out.size(), answers[id].size());
        std::copy(answers[id].begin(), answers[id].end(), out.begin());
        std::fill(samples.begin(), samples.end(), kUnknownSamples);
        return true;
    }
};

SchedulerParams twoPhase() {
    SchedulerParams p;
    p.mode = CullMode::TwoPhase;
    return p;
}

/// TestScene(_, 3)'s farthest row (z = -7) is hidden, the others visible: what only a
/// raster test can say, since the backend's depth hides nothing.
QueryResult farRowHidden(const QueryVolume& v) {
    float zMax = -1e30f;
    for (const glm::vec3& q : v.points()) zMax = std::max(zMax, q.z);
    return zMax < -6.0f ? QueryResult::Occluded : QueryResult::Visible;
}

}  // namespace

// With candidateRounds 2 the late pass's candidates are tested in two batches, the nearer
// half first, and the parts the first batch finds visible are drawn before the second is
// tested (so their depth can hide the farther half); the last round's answers still decide.
TEST(TwoPhaseRounds, NearerCandidatesAreTestedAndDrawnBeforeTheFartherHalf) {
    TestScene s(4, 3);  // rows at z = -3, -5, -7
    for (const std::uint32_t rounds : {1u, 2u}) {
        DepthBackend backend;
        std::vector<std::string> events;
        std::vector<float> batchNearest;  // per batch: its nearest volume's distance along -Z
        std::vector<float> batchFarthest;
        backend.rule = farRowHidden;
        struct Sink final : PartSink {
            std::vector<std::string>* events = nullptr;
            std::multiset<std::uint32_t> drawn;
            void drawPart(NodeRef part, std::uint32_t, std::uint32_t) override {
                drawn.insert(part.object);
                events->push_back("draw");
            }
        };
        struct Logged final : QueryBackend {
            DepthBackend* inner = nullptr;
            std::vector<std::string>* events = nullptr;
            std::vector<float>*nearest = nullptr, *farthest = nullptr;
            void beginFrame(const FrameView& v) override { inner->beginFrame(v); }
            void beginBatch() override { inner->beginBatch(); }
            QueryId issue(const QueryVolume& v) override { return inner->issue(v); }
            void endBatch() override {}
            QueryResult poll(QueryId id) override { return inner->poll(id); }
            QueryResult wait(QueryId id, double t) override { return inner->wait(id, t); }
            void release(QueryId) override {}
            bool readDepth(std::vector<float>& d, int& w, int& h) override { return inner->readDepth(d, w, h); }
            BatchId testVolumes(std::span<const QueryVolume> volumes, bool count) override {
                float lo = 1e30f, hi = -1e30f;
                for (const QueryVolume& v : volumes)
                    for (const glm::vec3& q : v.points()) lo = std::min(lo, -q.z), hi = std::max(hi, -q.z);
                nearest->push_back(lo);
                farthest->push_back(hi);
                events->push_back("test");
                return inner->testVolumes(volumes, count);
            }
            bool collectVolumes(BatchId id, std::span<QueryResult> out, double t, std::span<std::uint32_t> samples) override {
                return inner->collectVolumes(id, out, t, samples);
            }
        } logged;
        logged.inner = &backend;
        logged.events = &events;
        logged.nearest = &batchNearest;
        logged.farthest = &batchFarthest;
        SchedulerParams p = twoPhase();
        p.features.useCostModel = false;  // every part the pyramid lets through is a candidate
        p.tuning.candidateRounds = rounds;
        QueryScheduler sched(p);
        TwoLevelTree tree(s.bsp, s.objects);
        Sink sink;
        sink.events = &events;
        sched.cullFrame(tree, frontCamera(), 640, 320, logged, sink);
        // The first frame has no early set: every part is a candidate, the hidden row is not drawn.
        EXPECT_EQ(sink.drawn.size(), 8u) << rounds;
        // Candidate rounds, then the refresh test of the parts drawn.
        ASSERT_EQ(batchNearest.size(), rounds + 1) << rounds;
        if (rounds == 2) {
            EXPECT_LE(batchFarthest[0], batchNearest[1] + 2.0f) << "the first round holds the nearer candidates";
            EXPECT_LT(batchNearest[0], batchNearest[1]);
            const auto firstTest = std::find(events.begin(), events.end(), "test");
            const auto secondTest = std::find(firstTest + 1, events.end(), "test");
            EXPECT_GT(std::count(firstTest, secondTest, "draw"), 0) << "the first round's visible parts are drawn before the second round";
        }
    }
}

// splitDrawWaits (a measurement) waits for the drawing before every depth read and every
// raster test and times it apart; the decisions are the same as without it.
TEST(TwoPhaseStats, SplitDrawWaitsWaitsBeforeEveryReadAndTestAndDecidesAlike) {
    TestScene s(4, 3);
    std::multiset<std::uint32_t> drawn[2];
    for (const bool split : {false, true}) {
        DepthBackend backend;
        backend.rule = farRowHidden;
        SchedulerParams p = twoPhase();
        p.features.useCostModel = false;
        p.tuning.splitDrawWaits = split;
        QueryScheduler sched(p);
        TwoLevelTree tree(s.bsp, s.objects);
        FrameStats st;
        for (int f = 0; f < 3; ++f) {
            RecordingSink sink;
            st = sched.cullFrame(tree, frontCamera(), 640, 320, backend, sink);
            drawn[split] = sink.drawn;
        }
        if (split) {
            EXPECT_EQ(backend.finishes, backend.reads + backend.batches);
            EXPECT_GT(st.depthTests, 0u);
            EXPECT_GT(st.pyramidTestMs, 0.0);
            EXPECT_GE(st.drawWaitMs, 0.0);
        } else {
            EXPECT_EQ(backend.finishes, 0);
            EXPECT_EQ(st.drawWaitMs, 0.0);
            EXPECT_EQ(st.pyramidTestMs, 0.0);
        }
    }
    EXPECT_EQ(drawn[0], drawn[1]);
}

// Where the tests cull nothing (Sponza's case), the cost model stops testing after the
// first frame and probes again every probeFrames frames: by default at the frame's end,
// testing the parts drawn against a pyramid of the final depth (one read after every
// draw, no raster test); in the ablation with a frame that tests. Once occlusion appears,
// the next probe finds it and testing resumes. Every frame draws at least what vfc draws
// while nothing is occluded.
TEST(TwoPhaseCosts, TestsStopWhereTheyCullNothingAndResumeWhenTheyWould) {
    TestScene s(4, 3);
    const auto reference = vfcDrawn(s);
    TwoLevelTree tree(s.bsp, s.objects);
    SchedulerParams p = twoPhase();
    p.tuning.costs.probeFrames = 8;
    p.tuning.costs.depthReadNs = 1000.0;  // less than drawing this small scene's 144 triangles
    for (const bool endProbes : {true, false}) {
        SCOPED_TRACE(endProbes ? "probes at the frame's end" : "probes by frames that test");
        p.features.useEndProbes = endProbes;
        DepthBackend backend;
        QueryScheduler sched(p);
        std::vector<std::uint32_t> readFrames;
        for (std::uint32_t f = 1; f <= 20; ++f) {
            RecordingSink sink;
            std::size_t drawnAtRead = 0;
            backend.onRead = [&] { drawnAtRead = sink.drawn.size(); };
            const int reads = backend.reads, batches = backend.batches;
            const FrameStats st = sched.cullFrame(tree, frontCamera(), 640, 320, backend, sink);
            EXPECT_EQ(st.pyramidBuilds, static_cast<std::uint32_t>(backend.reads - reads)) << "a pyramid from every depth read";
            if (backend.reads > reads) readFrames.push_back(f);
            if (endProbes && f > 1 && backend.reads > reads) {
                EXPECT_EQ(backend.reads - reads, 1) << "frame " << f;
                EXPECT_EQ(drawnAtRead, sink.drawn.size()) << "frame " << f << ": read after every draw";
                EXPECT_EQ(backend.batches, batches) << "frame " << f << ": no raster test";
            }
            EXPECT_EQ(sink.drawn, reference) << "frame " << f;
        }
        EXPECT_EQ(readFrames, (std::vector<std::uint32_t>{1, 9, 17}));
        backend.onRead = nullptr;

        // Everything is hidden from now on: the probe at frame 25 finds it, and from the
        // frame after it nothing is drawn.
        backend.depth = 1.0f;
        backend.rule = [](const QueryVolume&) { return QueryResult::Occluded; };
        std::size_t drawnAt26 = 99, drawnAt27 = 99;
        for (std::uint32_t f = 21; f <= 27; ++f) {
            RecordingSink sink;
            sched.cullFrame(tree, frontCamera(), 640, 320, backend, sink);
            // Tests still off; a probe at the frame's end draws first.
            if (f < 25 || (endProbes && f == 25)) {
                EXPECT_EQ(sink.drawn, reference) << "frame " << f;
            }
            if (f == 26) drawnAt26 = sink.drawn.size();
            if (f == 27) drawnAt27 = sink.drawn.size();
        }
        EXPECT_EQ(drawnAt26, 0u);
        EXPECT_EQ(drawnAt27, 0u);
    }

    // The ablation tests every frame.
    p.features.useCostModel = false;
    QueryScheduler always(p);
    DepthBackend b2;
    for (int f = 0; f < 5; ++f) {
        RecordingSink sink;
        always.cullFrame(tree, frontCamera(), 640, 320, b2, sink);
    }
    EXPECT_EQ(b2.reads, 5);
}

// A frame that the cost model does not test has one traversal, front to back like vfc's.
// Drawing last frame's parts first would change only the order, and a worse order costs
// overdraw. The camera steps sideways each frame, so last frame's parts are not this one's.
TEST(TwoPhaseCosts, AFrameThatDoesNotTestDrawsInVfcsOrder) {
    TestScene s(6, 4);
    TwoLevelTree tree(s.bsp, s.objects);
    SchedulerParams vfc;
    vfc.mode = CullMode::Vfc;
    SchedulerParams p = twoPhase();
    p.tuning.costs.probeFrames = 1000;
    p.tuning.costs.depthReadNs = 1e12;  // no saving pays for a depth read
    QueryScheduler sched(p), reference(vfc);
    DepthBackend backend;
    ScriptedBackend none;
    int untested = 0;
    for (int f = 0; f < 6; ++f) {
        Camera cam = frontCamera();
        cam.position.x = cam.target.x = (f % 2 ? 2.5f : -2.5f);
        RecordingSink sink, expected;
        const int reads = backend.reads;
        sched.cullFrame(tree, cam, 640, 320, backend, sink);
        reference.cullFrame(tree, cam, 640, 320, none, expected);
        if (backend.reads > reads) continue;  // a frame that tests (the first)
        ++untested;
        EXPECT_EQ(sink.order, expected.order) << "frame " << f;
    }
    EXPECT_GE(untested, 5);
}

// A part is tested only if the drawing it may save outweighs the test: with drawing free,
// only the exploring eighth is tested and the rest drawn untested (VisibleCheaper); with
// drawing dear, every part the pyramid lets through is tested.
TEST(TwoPhaseCosts, PartsAreTestedOnlyWhereTheTestPays) {
    TestScene s(6, 4);
    const auto reference = vfcDrawn(s);
    TwoLevelTree tree(s.bsp, s.objects);
    for (double ns : {0.0, 1e6}) {
        SchedulerParams p = twoPhase();
        p.tuning.costs.drawNsPerTriangle = ns;
        QueryScheduler sched(p);
        DepthBackend backend;
        RecordingSink sink;
        std::vector<NodeTrace> trace;
        sched.setTrace(&trace);
        const FrameStats st = sched.cullFrame(tree, frontCamera(), 640, 320, backend, sink);
        EXPECT_EQ(sink.drawn, reference);
        std::size_t cheaper = 0, queried = 0;
        for (const NodeTrace& t : trace) {
            if (t.ref.isSceneNode()) continue;
            cheaper += t.state == NodeState::VisibleCheaper;
            queried += t.state == NodeState::VisibleQueried;
        }
        if (ns == 0.0) {
            EXPECT_LT(backend.tested, static_cast<int>(reference.size()) / 2) << "only the exploring parts";
            EXPECT_EQ(cheaper, st.skippedByCost);
            EXPECT_GT(cheaper, reference.size() / 2);
        } else {
            EXPECT_EQ(cheaper, 0u);
            EXPECT_EQ(st.skippedByCost, 0u);
            EXPECT_GE(queried, reference.size());
        }
    }
}

// A round of raster tests costs TestCosts::testNsPerBatch before its first volume: the
// late pass's candidates get a round only where their summed margins pay for it, else they
// are drawn untested, except every probeFrames frames, which keeps their rate measured.
// The far row is hidden, and only a raster test can say so.
TEST(TwoPhaseCosts, ARoundOfRasterTestsIsIssuedOnlyWhereItsCandidatesPayForIt) {
    TestScene s(4, 3);
    TwoLevelTree tree(s.bsp, s.objects);
    for (const double batchNs : {0.0, 1e11}) {
        SCOPED_TRACE("testNsPerBatch " + std::to_string(batchNs));
        DepthBackend backend;
        backend.rule = farRowHidden;
        SchedulerParams p = twoPhase();
        p.tuning.costs.drawNsPerTriangle = 1e6;  // every part alone is worth a test
        p.tuning.costs.testNsPerBatch = batchNs;
        p.tuning.costs.probeFrames = 4;
        QueryScheduler sched(p);
        int culling = 0, firstCulling = -1;
        for (int f = 0; f < 6; ++f) {
            SCOPED_TRACE("frame " + std::to_string(f));
            RecordingSink sink;
            const FrameStats st = sched.cullFrame(tree, frontCamera(), 640, 320, backend, sink);
            // A frame whose candidates were tested culls the far row; one that drew them
            // untested counts them skipped by the cost model.
            ASSERT_TRUE(sink.drawn.size() == 8u || sink.drawn.size() == 12u);
            if (sink.drawn.size() == 8u) {
                ++culling;
                if (firstCulling < 0) firstCulling = f;
            } else {
                EXPECT_GE(st.skippedByCost, 4u);
            }
        }
        if (batchNs == 0.0) {
            EXPECT_EQ(culling, 6);
        } else {
            EXPECT_EQ(culling, 1) << "the probe alone";
            EXPECT_GE(firstCulling, 3) << "after probeFrames frames";
        }
    }
}

// The first frame has no early depth: in full-hzb (no final-depth test) it measures no
// saving, and must not switch the tests off for it.
TEST(TwoPhaseCosts, AFrameWithoutEarlyDepthDoesNotTurnTheTestsOff) {
    TestScene s(4, 3);
    DepthBackend backend;
    SchedulerParams p = twoPhase();
    p.features.useBatchedRaster = false;
    p.tuning.costs.depthReadNs = 1000.0;
    QueryScheduler sched(p);
    TwoLevelTree tree(s.bsp, s.objects);
    RecordingSink first;
    sched.cullFrame(tree, frontCamera(), 640, 320, backend, first);
    EXPECT_EQ(first.drawn, vfcDrawn(s));
    backend.depth = 1.0f;  // everything hidden from now on
    RecordingSink second;
    sched.cullFrame(tree, frontCamera(), 640, 320, backend, second);
    EXPECT_EQ(backend.reads, 2);
    // The parts drawn early are last frame's; the late pass culls every other node.
    RecordingSink third;
    sched.cullFrame(tree, frontCamera(), 640, 320, backend, third);
    EXPECT_EQ(backend.reads, 3);
    EXPECT_TRUE(third.drawn.empty());
}

TEST(VisibilityHistory, ClusterBitsFollowTheObjectInTheirSlot) {
    // One bit per cluster of the object's model, cleared when created; kept for the same
    // object; cleared again when its slot is reused (generation) or its model changes.
    LocalBspParams fine;
    fine.maxLeafTriangles = 400;
    auto sphereBsp = buildLocalBsp(test::sphereGridMesh(64, 48, 0.5f), fine);
    ASSERT_TRUE(sphereBsp.ok());
    SceneObjects objects;
    const ModelId sphere = objects.addModel(sphereBsp.take());
    const ModelId cube = objects.addModel(cubeModel(0.4f));
    const std::size_t clusters = objects.model(sphere).clusters.clusters.size();
    ASSERT_GT(clusters, 64u);  // more than one word
    ObjectHandle a = objects.addObject(sphere, Transform{}).take();
    VisibilityHistory history;

    std::span<std::uint64_t> bits = history.clusterBits(a.index, objects);
    ASSERT_EQ(bits.size(), (clusters + 63) / 64);
    EXPECT_TRUE(std::all_of(bits.begin(), bits.end(), [](std::uint64_t w) { return w == 0; }));
    bits[0] = 0b101;
    bits[bits.size() - 1] = 1;
    history.at({a.index, 0}, objects).lastVisible = true;  // creating node records keeps the bits
    bits = history.clusterBits(a.index, objects);
    EXPECT_EQ(bits[0], 0b101u);
    EXPECT_EQ(bits[bits.size() - 1], 1u);

    // The slot reused by another sphere: nothing of the old object's bits is left.
    ASSERT_TRUE(objects.removeObject(a).ok());
    ObjectHandle b = objects.addObject(sphere, Transform{}).take();
    ASSERT_EQ(b.index, a.index);
    bits = history.clusterBits(b.index, objects);
    EXPECT_TRUE(std::all_of(bits.begin(), bits.end(), [](std::uint64_t w) { return w == 0; }));
    EXPECT_FALSE(history.at({b.index, 0}, objects).lastVisible);

    // Its model changed to a cube's: one leaf, a cluster or two, a fresh word.
    bits[0] = ~std::uint64_t{0};
    ASSERT_TRUE(objects.setModel(b, cube).ok());
    bits = history.clusterBits(b.index, objects);
    EXPECT_EQ(bits.size(), (objects.model(cube).clusters.clusters.size() + 63) / 64);
    EXPECT_TRUE(std::all_of(bits.begin(), bits.end(), [](std::uint64_t w) { return w == 0; }));
    history.clear();
    EXPECT_EQ(history.clusterBits(b.index, objects).size(), bits.size());
}

// The read-ahead's guess: with the left half of the screen hidden behind a near wall and
// the right half open, a hidden box shows after growing by about its pixel distance to the
// wall's edge (the pyramid reads a superset of the grown rectangle, so up to that distance
// rounded up to a power of two, never more, and a coarse level may see the edge sooner);
// a box deep behind the wall is far from showing; an open one, or one reaching the near
// plane, shows as it is; off screen or before any pyramid, nothing is known.
TEST(PixelsFromShowing, GrowsWithTheDistanceToTheSilhouette) {
    TestScene s(2, 1);
    TwoLevelTree tree(s.bsp, s.objects);
    DepthBackend backend;
    constexpr int kEdge = 320;
    backend.depthAt = [](int x, int) { return x < kEdge ? 1.0f : 0.0f; };  // reversed Z: 1 is the near plane
    QueryScheduler sched(twoPhase());
    const Aabb probe = Aabb::fromMinMax({-0.05f, -0.05f, -5.05f}, {0.05f, 0.05f, -4.95f});
    EXPECT_FALSE(sched.pixelsFromShowing(probe, 64)) << "no pyramid yet";
    RecordingSink sink;
    sched.cullFrame(tree, frontCamera(), 640, 320, backend, sink);

    const FrameView view = FrameView::of(frontCamera(), 640, 320);
    const ScreenProjection screen(view);
    float previous = 0.0f;
    int far = 0;
    // Boxes 0.1 wide at depth 5, from the open half across the edge to the screen's left side.
    for (float x = 1.0f; x > -9.0f; x -= 0.05f) {
        const Aabb box = Aabb::fromMinMax({x - 0.05f, -0.05f, -5.05f}, {x + 0.05f, 0.05f, -4.95f});
        ScreenRect rect;
        ASSERT_TRUE(screen.rect(box, rect));
        if (rect.empty() || rect.x0 <= 0) break;  // leaving the screen
        const auto pixels = sched.pixelsFromShowing(box, 64);
        ASSERT_TRUE(pixels) << "x " << x;
        const int gap = kEdge - rect.x1;  // pixels between the box and the open half
        if (gap < -1) {
            EXPECT_EQ(*pixels, 0.0f) << "x " << x;  // over the open half
        } else if (gap > 2) {
            EXPECT_GT(*pixels, 0.0f) << "x " << x;
            // (rect is padded by a pixel beyond the pixel centres the box covers)
            if (gap + 2 <= 64) {
                EXPECT_LE(*pixels, float(std::bit_ceil(unsigned(gap + 2)))) << "x " << x << " gap " << gap;
            }
        }
        EXPECT_GE(*pixels, previous) << "further from the edge, never nearer to showing (x " << x << ")";
        previous = *pixels;
        far += *pixels == QueryScheduler::kFarFromShowing;
    }
    EXPECT_GT(far, 0) << "boxes deep behind the wall";
    // Through the near plane: visible without a guess.
    EXPECT_EQ(sched.pixelsFromShowing(Aabb::fromMinMax({-3.0f, -1.0f, -1.0f}, {-2.0f, 1.0f, 1.0f}), 64), 0.0f);
    // Behind the camera, or off to the side: nothing to say.
    EXPECT_FALSE(sched.pixelsFromShowing(Aabb::fromMinMax({40.0f, -1.0f, -6.0f}, {41.0f, 1.0f, -5.0f}), 64));
}
