#include <algorithm>
#include <random>

#include <gtest/gtest.h>

#include "bsp_test_models.hpp"
#include "dyncull/bsp/loose_bsp.hpp"
#include "dyncull/objects/motion.hpp"
#include "objects/transform_at.hpp"

using namespace dyncull;

namespace {

using test::at;

std::uint32_t maxObjectsInNode(const LooseBsp& bsp) {
    std::uint32_t m = 0;
    for (const auto& n : bsp.nodes()) m = std::max(m, n.objectCount);
    return m;
}

struct RunResult {
    std::vector<std::uint32_t> assignments;  // node of every slot, every frame, concatenated
    std::uint32_t maxDepth = 0, maxPerNode = 0, rebuilds = 0, relinked = 0;
};

// 500 cubes bouncing in a 100^3 box for `frames` frames; every 10th frame one object is
// removed and re-added, every 50th frame one object jumps across the whole world.
RunResult motionRun(std::uint32_t frames, double budgetMs, bool record) {
    const std::uint32_t count = 500;
    const Aabb world = Aabb::fromMinMax(glm::vec3(-50.0f), glm::vec3(50.0f));
    BouncingMotion motion(count, world, 0.7f, 1.0f, 1234);
    SceneObjects so;
    const ModelId m = so.addModel(test::cubeModel());
    std::vector<ObjectHandle> handles;
    for (std::uint32_t i = 0; i < count; ++i) handles.push_back(so.addObject(m, at(motion.position(i, 0))).take());
    LooseBspParams params;
    params.rebuildBudgetMs = budgetMs;
    LooseBsp bsp(params);
    bsp.build(so);
    EXPECT_EQ(bsp.validate(so), "");
    std::mt19937 rng(99);
    RunResult r;
    for (std::uint32_t f = 1; f <= frames; ++f) {
        for (std::uint32_t i = 0; i < count; ++i) {
            glm::vec3 p = motion.position(i, f);
            if (f % 50 == 0 && i == f % count) p = -p;  // crosses the whole world in one frame
            EXPECT_TRUE(so.setTransform(handles[i], at(p)).ok());
        }
        if (f % 10 == 0) {
            const std::uint32_t i = rng() % count;
            const ObjectHandle old = handles[i];
            EXPECT_TRUE(so.removeObject(old).ok());
            handles[i] = so.addObject(m, at(motion.position(i, f))).take();
            EXPECT_EQ(handles[i].generation, old.generation + 1);
        }
        const LooseBspFrameStats s = bsp.update(so);
        r.rebuilds += s.rebuilds;
        r.relinked += s.relinked;
        const std::string v = bsp.validate(so);
        if (!v.empty()) {
            ADD_FAILURE() << "frame " << f << ": " << v;
            return r;
        }
        EXPECT_EQ(bsp.nodes()[0].subtreeObjects, count);  // nothing lost
        r.maxDepth = std::max(r.maxDepth, bsp.depth());
        r.maxPerNode = std::max(r.maxPerNode, maxObjectsInNode(bsp));
        if (record)
            for (std::uint32_t i = 0; i < so.slotCount(); ++i) r.assignments.push_back(bsp.nodeOf(i));
    }
    return r;
}

}  // namespace

TEST(LooseBsp, LongMotionRunStaysValidBoundedAndDeterministic) {
    // Unlimited budget: every pending rebuild runs, so the run is independent of timing.
    const RunResult a = motionRun(2000, 1e9, true);
    const RunResult b = motionRun(2000, 1e9, true);
    EXPECT_EQ(a.assignments, b.assignments);
    EXPECT_GT(a.relinked, 10000u);
    EXPECT_GT(a.rebuilds, 0u);
    // log2(500 / 4) ~ 7 balanced levels; allow drift between rebuilds.
    EXPECT_LE(a.maxDepth, 20u);
    // Objects straddling high split planes collect in inner nodes; far below 500.
    EXPECT_LE(a.maxPerNode, 60u);
}

TEST(LooseBsp, RealTimeBudgetRunStaysValid) {
    const RunResult r = motionRun(300, 0.5, false);
    EXPECT_LE(r.maxDepth, 24u);
}

TEST(LooseBsp, BuildPlacesEachObjectInSmallestContainingNode) {
    SceneObjects so;
    const ModelId m = so.addModel(test::cubeModel());
    for (int i = 0; i < 64; ++i) so.addObject(m, at({float(i % 4) * 10.0f, float(i / 4 % 4) * 10.0f, float(i / 16) * 10.0f})).take();
    const ObjectHandle big = so.addObject(m, at({15.0f, 15.0f, 15.0f}, 40.0f)).take();
    LooseBsp bsp;
    bsp.build(so);
    EXPECT_EQ(bsp.validate(so), "");
    EXPECT_TRUE(so.added().empty());  // consumed
    EXPECT_EQ(bsp.nodeOf(big.index), bsp.root());  // spans every split plane
    for (const auto& n : bsp.nodes())
        if (n.isLeaf()) {
            EXPECT_LE(n.objectCount, 4u);
        }
}

TEST(LooseBsp, ObjectLeavingRootCellGrowsRoot) {
    SceneObjects so;
    const ModelId m = so.addModel(test::cubeModel());
    std::vector<ObjectHandle> hs;
    for (int i = 0; i < 40; ++i) hs.push_back(so.addObject(m, at({float(i), float(i % 7), 0.0f})).take());
    LooseBsp bsp;
    bsp.build(so);
    const Aabb before = bsp.nodes()[0].cell;
    ASSERT_TRUE(so.setTransform(hs[3], at({1e4f, -1e4f, 5e3f})).ok());
    const LooseBspFrameStats s = bsp.update(so);
    EXPECT_GE(s.rootGrowths, 1u);
    EXPECT_TRUE(bsp.nodes()[0].cell.contains(before));
    EXPECT_TRUE(bsp.nodes()[0].cell.contains(so.worldBox(hs[3].index)));
    EXPECT_EQ(bsp.validate(so), "");
    // Keep walking away: doubling keeps the number of growths logarithmic.
    std::uint32_t growths = 0;
    for (int f = 1; f <= 100; ++f) {
        ASSERT_TRUE(so.setTransform(hs[5], at({-100.0f * float(f * f), 0.0f, 0.0f})).ok());
        growths += bsp.update(so).rootGrowths;
        ASSERT_EQ(bsp.validate(so), "") << "frame " << f;
    }
    EXPECT_LE(growths, 30u);
}

TEST(LooseBsp, UpdateWithoutBuildAndRemoveReAddInSameFrame) {
    SceneObjects so;
    const ModelId m = so.addModel(test::cubeModel());
    LooseBsp bsp;
    std::vector<ObjectHandle> hs;
    for (int i = 0; i < 30; ++i) hs.push_back(so.addObject(m, at({float(i) * 3.0f, 0.0f, float(i % 3)})).take());
    bsp.update(so);  // empty tree: the root cell grows around the first objects
    EXPECT_EQ(bsp.validate(so), "");
    EXPECT_EQ(bsp.nodes()[0].subtreeObjects, 30u);
    // Removed and its slot re-added in the same frame; another added and removed at once.
    ASSERT_TRUE(so.removeObject(hs[4]).ok());
    const ObjectHandle again = so.addObject(m, at({-20.0f, 0.0f, 0.0f})).take();
    EXPECT_EQ(again.index, hs[4].index);
    const ObjectHandle brief = so.addObject(m, at({1.0f, 1.0f, 1.0f})).take();
    ASSERT_TRUE(so.removeObject(brief).ok());
    ASSERT_TRUE(so.setTransform(again, at({-21.0f, 0.0f, 0.0f})).ok());
    bsp.update(so);
    EXPECT_EQ(bsp.validate(so), "");
    EXPECT_EQ(bsp.nodes()[0].subtreeObjects, 30u);
    // Remove everything, then add back.
    for (std::uint32_t i = 0; i < so.slotCount(); ++i)
        if (so.alive(i)) {
            ASSERT_TRUE(so.removeObject(so.handle(i)).ok());
        }
    bsp.update(so);
    EXPECT_EQ(bsp.validate(so), "");
    EXPECT_EQ(bsp.nodes()[0].subtreeObjects, 0u);
    for (int i = 0; i < 10; ++i) so.addObject(m, at({0.0f, float(i), 0.0f})).take();
    bsp.update(so);
    EXPECT_EQ(bsp.validate(so), "");
}

TEST(LooseBsp, StaticFramesChangeNothing) {
    SceneObjects so;
    const ModelId m = so.addModel(test::cubeModel());
    for (int i = 0; i < 200; ++i) so.addObject(m, at({float(i % 13) * 2.0f, float(i % 7) * 2.0f, float(i % 5) * 2.0f}), true).take();
    LooseBsp bsp;
    bsp.build(so);
    const auto before = bsp.nodes();
    for (int f = 0; f < 10; ++f) {
        const LooseBspFrameStats s = bsp.update(so);
        EXPECT_EQ(s.relinked, 0u);
        EXPECT_EQ(s.rebuilds, 0u);
    }
    ASSERT_EQ(bsp.nodes().size(), before.size());
    for (std::size_t i = 0; i < before.size(); ++i) EXPECT_EQ(bsp.nodes()[i].box.min, before[i].box.min);
}

TEST(LooseBsp, ClusterThatSpreadsOutIsLazilyRebuilt) {
    SceneObjects so;
    const ModelId m = so.addModel(test::cubeModel(0.05f));
    std::vector<ObjectHandle> hs;
    // 300 objects start on a line at one end, then spread over the whole box.
    for (int i = 0; i < 300; ++i) hs.push_back(so.addObject(m, at({float(i) * 0.2f, 0.0f, 0.0f})).take());
    LooseBspParams p;
    p.rebuildBudgetMs = 1e9;
    LooseBsp bsp(p);
    bsp.build(so);
    std::mt19937 rng(5);
    std::uniform_real_distribution<float> u(-500.0f, 500.0f);
    for (auto h : hs) ASSERT_TRUE(so.setTransform(h, at({u(rng), u(rng), u(rng)})).ok());
    LooseBspFrameStats s = bsp.update(so);
    EXPECT_EQ(bsp.validate(so), "");
    EXPECT_GT(s.rebuilds, 0u);
    for (int f = 0; f < 5; ++f) bsp.update(so);
    EXPECT_EQ(bsp.validate(so), "");
    std::uint32_t maxLeaf = 0;
    for (const auto& n : bsp.nodes())
        if (n.isLeaf()) maxLeaf = std::max(maxLeaf, n.objectCount);
    EXPECT_LE(maxLeaf, 2 * p.maxObjectsPerLeaf);
}

TEST(LooseBsp, DegenerateAllObjectsAtOnePosition) {
    SceneObjects so;
    const ModelId m = so.addModel(test::cubeModel());
    for (int i = 0; i < 1000; ++i) so.addObject(m, at({3.0f, 3.0f, 3.0f})).take();
    LooseBsp bsp;
    bsp.build(so);
    EXPECT_EQ(bsp.validate(so), "");
    EXPECT_LE(bsp.depth(), 1u);  // no split separates them: stop without progress
    EXPECT_EQ(bsp.update(so).rebuilds, 0u);
}

TEST(LooseBsp, DegenerateZeroSizeBoxesOnSplitPlanes) {
    SceneObjects so;
    const ModelId point = so.addModel(test::cubeModel(0.0f));
    std::vector<ObjectHandle> hs;
    for (int i = 0; i < 400; ++i) hs.push_back(so.addObject(point, at({float(i % 2), float(i % 3), float(i % 4)})).take());
    LooseBsp bsp;
    bsp.build(so);
    EXPECT_EQ(bsp.validate(so), "");
    // Move them onto exact split values of the tree.
    for (std::size_t i = 0; i < hs.size(); ++i) {
        const auto& n = bsp.nodes()[i % bsp.nodes().size()];
        glm::vec3 p(0.5f);
        p[n.axis] = n.split;
        ASSERT_TRUE(so.setTransform(hs[i], at(p)).ok());
    }
    bsp.update(so);
    EXPECT_EQ(bsp.validate(so), "");
}

TEST(LooseBsp, DegenerateHugeCoordinatesAndExtremeScales) {
    SceneObjects so;
    const ModelId m = so.addModel(test::cubeModel());
    std::vector<ObjectHandle> hs;
    std::mt19937 rng(7);
    std::uniform_real_distribution<float> u(-1000.0f, 1000.0f);
    for (int i = 0; i < 300; ++i) {
        const float s = (i % 3 == 0) ? 1e-6f : (i % 3 == 1 ? 1.0f : 1e6f);
        hs.push_back(so.addObject(m, at({1e7f + u(rng), -1e7f + u(rng), u(rng)}, s)).take());
    }
    LooseBsp bsp;
    bsp.build(so);
    EXPECT_EQ(bsp.validate(so), "");
    for (int f = 0; f < 20; ++f) {
        for (std::size_t i = 0; i < hs.size(); ++i) {
            const float s = (i % 3 == 0) ? 1e-6f : (i % 3 == 1 ? 1.0f : 1e6f);
            ASSERT_TRUE(so.setTransform(hs[i], at({1e7f + u(rng), -1e7f + u(rng), u(rng) * float(f)}, s)).ok());
        }
        bsp.update(so);
        ASSERT_EQ(bsp.validate(so), "") << "frame " << f;
    }
}

TEST(LooseBsp, MemoryPerObjectIsBounded) {
    SceneObjects so;
    const ModelId m = so.addModel(test::cubeModel(0.2f));
    std::mt19937 rng(11);
    std::uniform_real_distribution<float> u(-300.0f, 300.0f);
    const int n = 20000;
    for (int i = 0; i < n; ++i) so.addObject(m, at({u(rng), u(rng), u(rng)})).take();
    LooseBsp bsp;
    bsp.build(so);
    EXPECT_EQ(bsp.validate(so), "");
    EXPECT_LE(bsp.memoryBytes(), 128u * n);
}
