// Ground truth by the ID pass on hand-made scenes: hidden parts are not visible, pixel
// counts add up to the covered pixels, and coverage matches the renderer's own image
// pixel for pixel. Also the drawn leaves, the per-object answers and the part comparison.
#include <gtest/gtest.h>

#include <glm/gtc/quaternion.hpp>

#include "dyncull/engine/engine.hpp"
#include "dyncull/measure/ground_truth.hpp"
#include "engine/gl_test_util.hpp"
#include "engine/procedural_meshes.hpp"
#include "objects/transform_at.hpp"

namespace dyncull {
namespace {

using test::cameraOnZ;
using test::headless;
using test::isClear;

using test::at;

struct QuadAndCube : ::testing::Test {
    std::unique_ptr<GlContext> ctx = headless();
    std::unique_ptr<Engine> engine;
    std::unique_ptr<GroundTruth> truth;
    ObjectHandle quad, cube, faraway;

    void SetUp() override {
        ASSERT_TRUE(ctx);
        auto e = Engine::create(*ctx);
        ASSERT_TRUE(e.ok());
        engine = e.take();
        auto g = GroundTruth::create(*ctx);
        ASSERT_TRUE(g.ok()) << g.error().message;
        truth = g.take();
        const ModelId quadModel = *engine->addModel(test::quadMesh(1.0f));
        const ModelId cubeModel = *engine->addModel(test::cubeMesh(0.4f));
        quad = *engine->addObject(quadModel, at({0, 0, 0}));
        cube = *engine->addObject(cubeModel, at({0, 0, -2}));  // right behind the quad
        faraway = *engine->addObject(cubeModel, at({50, 0, 0}));  // outside the frustum
        ASSERT_TRUE(engine->setCamera(cameraOnZ(3.0f)).ok());
        SchedulerParams vfc;
        vfc.mode = CullMode::Vfc;
        ASSERT_TRUE(engine->setSchedulerParams(vfc).ok());
    }

    /// Renders vfc and checks the ID image against it pixel by pixel.
    void expectCoverageMatchesRender(const VisibleSet& vs) {
        ctx->clearFramebuffer(Renderer::kClearColour);
        ASSERT_TRUE(engine->renderFrame().ok());
        const Image img = engine->renderer().readPixels();
        const std::vector<std::uint32_t>& ids = truth->idImage();
        ASSERT_EQ(ids.size(), static_cast<std::size_t>(img.width) * static_cast<std::size_t>(img.height));
        std::uint64_t nonClear = 0, mismatched = 0;
        for (int y = 0; y < img.height; ++y)
            for (int x = 0; x < img.width; ++x) {
                const bool covered = ids[static_cast<std::size_t>(y * img.width + x)] != 0;
                const bool drawn = !isClear(img.at(x, y));
                nonClear += drawn;
                mismatched += covered != drawn;
            }
        EXPECT_EQ(mismatched, 0u);
        EXPECT_EQ(nonClear, vs.coveredPixels);
        EXPECT_EQ(vs.artefactPixels, 0u);  // every fragment lies within its box's depth range
    }
};

TEST_F(QuadAndCube, HiddenCubeIsNotVisible) {
    const VisibleSet vs = truth->compute(*engine, engine->camera());
    EXPECT_EQ(vs.candidates, 2u);  // the far cube is frustum-culled
    ASSERT_EQ(vs.parts.size(), 1u);
    EXPECT_EQ(vs.parts[0], (NodeRef{quad.index, 0}));
    EXPECT_FALSE(vs.contains({cube.index, 0}));
    EXPECT_EQ(vs.pixelsOf({cube.index, 0}), 0u);
    EXPECT_EQ(vs.pixels[0], vs.coveredPixels);
    // Quad of half-size 1 at distance 3, fov 0.9: about 2 / (2 * 3 tan 0.45) of 64 per side.
    EXPECT_GT(vs.coveredPixels, 1600u);
    EXPECT_LT(vs.coveredPixels, 2400u);
    expectCoverageMatchesRender(vs);
}

TEST_F(QuadAndCube, PartlyHiddenCubeCountsItsOwnPixels) {
    ASSERT_TRUE(engine->setTransform(cube, at({2.0f, 0, -2})).ok());  // sticks out right of the quad
    const VisibleSet vs = truth->compute(*engine, engine->camera());
    ASSERT_EQ(vs.parts.size(), 2u);
    const std::uint32_t q = vs.pixelsOf({quad.index, 0}), c = vs.pixelsOf({cube.index, 0});
    EXPECT_GT(q, 0u);
    EXPECT_GT(c, 0u);
    EXPECT_EQ(std::uint64_t{q} + c, vs.coveredPixels);
    expectCoverageMatchesRender(vs);
}

TEST_F(QuadAndCube, MirroredCulledCubeIsSeenAsTheRendererDrawsIt) {
    // The cube is closed and outward, so both passes cull its back faces; a mirroring
    // transform turns its triangles clockwise, which both must account for, or the ID pass
    // would see the cube's inside (or nothing) where the renderer drew its outside.
    ASSERT_EQ(engine->model(engine->objects().modelOf(cube.index)).faces, FaceMode::CullBack);
    Transform mirrored = at({0.3f, 0.2f, 1.0f});
    mirrored.scale = {-1.0f, 1.0f, 1.0f};
    mirrored.rotation = glm::angleAxis(0.5f, glm::normalize(glm::vec3(1, 2, 3)));
    ASSERT_TRUE(engine->setTransform(cube, mirrored).ok());
    const VisibleSet vs = truth->compute(*engine, engine->camera());
    EXPECT_GT(vs.pixelsOf({cube.index, 0}), 100u);
    expectCoverageMatchesRender(vs);
}

TEST_F(QuadAndCube, DrawnPartsAreComparedWithTheTruth) {
    const VisibleSet vs = truth->compute(*engine, engine->camera());
    ctx->clearFramebuffer(Renderer::kClearColour);
    ASSERT_TRUE(engine->renderFrame().ok());  // vfc draws quad and hidden cube
    const PartErrors e = compareParts(vs, drawnLeaves(engine->objects(), engine->visibleParts()));
    EXPECT_EQ(e.drawn, 2u);
    EXPECT_EQ(e.falseNegatives, 0u);
    EXPECT_EQ(e.falsePositives, 1u);
    const PartErrors none = compareParts(vs, {});
    EXPECT_EQ(none.falseNegatives, 1u);
    EXPECT_EQ(none.falseNegativePixels, vs.coveredPixels);
    // The oracle path draws exactly the visible set and gives the same picture as vfc.
    const Image vfcImage = engine->renderer().readPixels();
    ctx->clearFramebuffer(Renderer::kClearColour);
    // The per-object answers of that frame: quad and cube drawn, the far cube culled.
    EXPECT_TRUE(engine->isVisible(quad));
    EXPECT_TRUE(engine->isVisible(cube));
    EXPECT_FALSE(engine->isVisible(faraway));
    EXPECT_EQ(engine->visibleObjects().size(), 2u);
    const FrameStats st = *engine->renderParts({{quad.index, 0}});
    EXPECT_EQ(st.partsDrawn, 1u);
    ASSERT_EQ(engine->visibleObjects().size(), 1u);
    EXPECT_EQ(engine->visibleObjects()[0], quad);
    EXPECT_FALSE(engine->isVisible(cube));
    ASSERT_EQ(engine->visibleParts().size(), 1u);
    EXPECT_EQ(engine->visibleParts()[0].part, (NodeRef{quad.index, 0}));
    // A removed object is not visible, and its stale handle never will be.
    ASSERT_TRUE(engine->removeObject(quad).ok());
    EXPECT_FALSE(engine->isVisible(quad));
    EXPECT_EQ(engine->renderer().readPixels().rgba, vfcImage.rgba);
    EXPECT_EQ(ctx->checkErrors(), 0u);
}

TEST(GroundTruthArtefacts, FragmentsOutsideTheirBoxDepthRangeAreNotCounted) {
    // A rasteriser that writes a fragment nearer or farther than anything its part's box
    // can hold (llvmpipe does, rarely, for tiny edge-on triangles) is imitated by a model
    // whose stored box was moved behind its geometry: every pixel is then an artefact.
    std::unique_ptr<GlContext> ctx = headless();
    ASSERT_TRUE(ctx);
    auto e = Engine::create(*ctx);
    ASSERT_TRUE(e.ok());
    std::unique_ptr<Engine> engine = e.take();
    auto g = GroundTruth::create(*ctx);
    ASSERT_TRUE(g.ok());
    std::unique_ptr<GroundTruth> truth = g.take();
    auto honest = buildLocalBsp(test::quadMesh(1.0f));
    ASSERT_TRUE(honest.ok());
    LocalBsp shifted = *honest;
    ASSERT_EQ(shifted.nodes.size(), 1u);
    shifted.nodes[0].box.min.z -= 2.0f;  // the quad (z = 0) lies in front of [-2, -2 + thickness]
    shifted.nodes[0].box.max.z -= 2.0f;
    const ModelId good = *engine->addModel(honest.take());
    const ModelId bad = *engine->addModel(std::move(shifted));
    const ObjectHandle a = *engine->addObject(good, at({-1.2f, 0, 0}));
    const ObjectHandle b = *engine->addObject(bad, at({1.2f, 0, 0}));
    ASSERT_TRUE(engine->setCamera(cameraOnZ(4.0f)).ok());
    const VisibleSet vs = truth->compute(*engine, engine->camera());
    ASSERT_EQ(vs.parts.size(), 1u);
    EXPECT_EQ(vs.parts[0], (NodeRef{a.index, 0}));
    EXPECT_FALSE(vs.contains({b.index, 0}));
    // The two quads are mirror images on screen, so the artefacts are about as many
    // pixels as the honest quad owns.
    EXPECT_GT(vs.artefactPixels, vs.coveredPixels * 9 / 10);
    EXPECT_LT(vs.artefactPixels, vs.coveredPixels * 11 / 10);
    for (std::uint32_t id : truth->idImage()) {
        if (id != 0) {
            EXPECT_EQ(truth->lastParts()[id - 1], (NodeRef{a.index, 0}));
        }
    }
}

TEST(DrawnLeaves, PartsMapToTheLeavesTheyCover) {
    SceneObjects objects;
    LocalBspParams p;
    p.maxLeafTriangles = 40;
    auto bsp = buildLocalBsp(test::sphereMesh(1.0f, 12, 24), p);
    ASSERT_TRUE(bsp.ok());
    const ModelId model = objects.addModel(bsp.take());
    const ObjectHandle h = *objects.addObject(model, Transform{});
    const LocalBsp& b = objects.model(model);
    std::uint32_t leaves = 0, someLeaf = 0;
    for (std::uint32_t i = 0; i < b.nodes.size(); ++i)
        if (b.nodes[i].isLeaf() && b.nodes[i].indexCount > 0) {
            ++leaves;
            someLeaf = i;
        }
    ASSERT_GT(leaves, 4u);
    auto part = [&](std::uint32_t node) {
        return VisiblePart{h, NodeRef{h.index, node}, b.nodes[node].firstIndex, b.nodes[node].indexCount};
    };
    const std::vector<VisiblePart> one = {part(someLeaf)};
    const std::vector<NodeRef> leafOnly = drawnLeaves(objects, one);
    ASSERT_EQ(leafOnly.size(), 1u);
    EXPECT_EQ(leafOnly[0], (NodeRef{h.index, someLeaf}));
    const std::vector<VisiblePart> rootAndLeaf = {part(0), part(someLeaf)};  // a whole subtree, and a duplicate
    EXPECT_EQ(drawnLeaves(objects, rootAndLeaf).size(), leaves);
}

}  // namespace
}  // namespace dyncull
