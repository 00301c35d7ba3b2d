// Near plane 1e-4 with far plane 1e7 through the whole pipeline (issue: robustness,
// numerical extremes): reversed-Z depth (docs/ARCHITECTURE.md, "Depth convention").
//
// The reference is independent of the 1e11 near/far ratio: the scene is built of depth
// layers a decade apart, each rendered alone with near/far planes fitted to it (ratio 10),
// then composited far to near (painter's algorithm, exact because layers do not overlap in
// depth). Screen x/y of a vertex does not depend on near/far, so a correct full-range
// render matches the composite pixel for pixel; only depth order can differ. The same is
// done with the ID pass for the reference visible set.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <set>
#include <utility>

#include "engine/extremes_rig.hpp"
#include "engine/procedural_meshes.hpp"

namespace dyncull {
namespace {

using test::kHeight;
using test::kWidth;
using test::Rig;

constexpr float kNear = 1e-4f, kFar = 1e7f;

/// Two parallel quads facing +Z in one mesh: the back one (half size `backHalf`, at
/// z = -gap) first in index order, then the front one (at z = 0).
Mesh twoQuads(float frontHalf, float backHalf, float gap) {
    Mesh m;
    m.name = "two quads";
    for (const auto& [h, z] : {std::pair(backHalf, -gap), std::pair(frontHalf, 0.0f)}) {
        const auto base = static_cast<std::uint32_t>(m.positions.size());
        m.positions.insert(m.positions.end(), {{-h, -h, z}, {h, -h, z}, {h, h, z}, {-h, h, z}});
        m.indices.insert(m.indices.end(), {base, base + 1, base + 2, base, base + 2, base + 3});
    }
    m.normals.assign(m.positions.size(), {0, 0, 1});
    return m;
}

/// Camera at the origin looking down -Z; a point at view depth d and screen tangents
/// (tx, ty) sits at (tx d, ty d, -d).
Camera camera(float nearPlane, float farPlane) { return test::look({0, 0, 0}, {0, 0, -1}, nearPlane, farPlane); }

struct NearFarScene {
    Rig rig;
    struct Placed {
        ObjectHandle handle;
        int layer = 0;        ///< decade of the view depth: the reference renders it alone
        bool hidden = false;  ///< fully behind a nearer object by construction
        const char* what = "";
    };
    std::vector<Placed> placed;

    NearFarScene() {
        if (!rig.ok()) return;
        LocalBspParams split;
        split.maxLeafTriangles = 128;  // hidden spheres have several parts each
        const ModelId cube = rig.model(test::cubeMesh(0.5f)), quad = rig.model(test::quadMesh(1.0f)),
                      sphere = rig.model(test::sphereMesh(0.5f, 16, 32)),
                      splitSphere = rig.model(test::sphereMesh(0.5f, 16, 32), split);
        int colour = 0;
        auto add = [&](ModelId m, glm::vec3 at, float scale, int layer, bool hidden, const char* what) {
            const ObjectHandle h = rig.object(m, at, glm::vec3(scale));
            static const glm::vec3 palette[] = {{0.9f, 0.2f, 0.2f}, {0.2f, 0.85f, 0.2f}, {0.25f, 0.35f, 0.95f},
                                                {0.95f, 0.85f, 0.2f}, {0.85f, 0.3f, 0.9f}, {0.2f, 0.9f, 0.9f},
                                                {0.95f, 0.6f, 0.2f}};
            rig.engine->setColour(h, palette[colour++ % 7]);
            placed.push_back({h, layer, hidden, what});
        };
        // (a) Cubes whose front faces are 1e-3, 1e-2 and 1e-1 from the eye, each covering
        // +-0.08 in screen tangent, hiding a split sphere (+-0.025) 1e3 times further away.
        for (int i = 0; i < 3; ++i) {
            const float front = std::pow(10.0f, float(i - 3)), half = 0.08f * front;
            const glm::vec2 t(-0.45f, 0.3f - 0.3f * float(i));
            add(cube, glm::vec3(t * front, -(front + half)), 2.0f * half, i - 3, false, "near occluder cube");
            const float d = front * 1e3f;
            add(splitSphere, glm::vec3(t * d, -d), 0.05f * d, i, true, "sphere behind a near cube");
        }
        // (b) Quads 1e-5 of their distance apart at 1e3 and 1e5: standard [-1, 1] float depth
        // gives both the same depth value there (its resolution at 1e3 is ~300 units, and
        // beyond ~3,400 units everything is exactly 1.0), reversed Z separates them. At 1e5
        // two pairs of objects: the far quad framing the near one, and fully behind it. At
        // 1e3 one mesh holding both quads, the far one first in index order, so a depth tie
        // shows the far quad (drawing order cannot hide the tie).
        for (const float ty : {0.3f, -0.3f}) {
            const float d = 1e5f, gap = 1e-5f * d, frontHalf = ty > 0 ? 0.05f : 0.1f, backHalf = ty > 0 ? 0.1f : 0.05f;
            add(quad, {0, ty * d, -d}, frontHalf * d, 5, false, "front quad of a pair at 1e5");
            add(quad, {0, ty * (d + gap), -(d + gap)}, backHalf * d, 5, backHalf < frontHalf, "back quad of a pair at 1e5");
        }
        add(rig.model(twoQuads(0.05f * 1e3f, 0.1f * 1e3f, 1e-5f * 1e3f)), {0, 0, -1e3f}, 1.0f, 3, false,
            "two quads 0.01 apart at 1e3");
        // (c) Spheres at 1e-3, 1e-2, ..., 1e6 on a diagonal, each overlapping the next a little.
        for (int k = -3; k <= 6; ++k) {
            const float d = std::pow(10.0f, float(k));
            const glm::vec2 t(0.3f + 0.03f * float(k + 3), -0.4f + 0.085f * float(k + 3));
            add(sphere, glm::vec3(t * d, -d), 0.11f * d, k, false, "sphere of the 1e-3..1e6 diagonal");
        }
    }

    std::vector<NodeRef> partsOfLayer(int layer) const {
        std::vector<NodeRef> parts;
        for (const Placed& p : placed)
            if (p.layer == layer) parts.push_back({p.handle.index, 0});  // root node: the whole object
        return parts;
    }

    struct Reference {
        Image image;
        VisibleSet visible;
    };
    /// Layers far to near, each alone with near/far = [0.3, 3] x its decade, composited.
    Reference reference() {
        Reference ref;
        const Camera any = camera(1.0f, 10.0f);
        EXPECT_TRUE(rig.engine->setCamera(any).ok());
        rig.ctx->clearFramebuffer(Renderer::kClearColour);
        EXPECT_TRUE(rig.engine->renderParts({}).ok());
        const Image background = rig.engine->renderer().readPixels();
        ref.image = background;
        std::vector<std::uint32_t> partAt(static_cast<std::size_t>(kWidth * kHeight), 0);
        std::vector<NodeRef> partOfId;  // 1-based ids into this list
        for (int layer = 6; layer >= -3; --layer) {
            const float decade = std::pow(10.0f, float(layer));
            const Camera c = camera(0.3f * decade, 3.0f * decade);
            EXPECT_TRUE(rig.engine->setCamera(c).ok());
            rig.ctx->clearFramebuffer(Renderer::kClearColour);
            EXPECT_TRUE(rig.engine->renderParts(partsOfLayer(layer)).ok());
            const Image img = rig.engine->renderer().readPixels();
            for (std::size_t i = 0; i < img.rgba.size(); i += 4)
                if (!std::equal(&img.rgba[i], &img.rgba[i] + 4, &background.rgba[i]))
                    std::copy_n(&img.rgba[i], 4, &ref.image.rgba[i]);
            rig.truth->compute(*rig.engine, c);
            const auto& ids = rig.truth->idImage();
            const auto& parts = rig.truth->lastParts();
            for (std::size_t i = 0; i < ids.size(); ++i)
                if (ids[i] != 0) {
                    partOfId.push_back(parts[ids[i] - 1]);
                    partAt[i] = static_cast<std::uint32_t>(partOfId.size());
                }
        }
        std::map<NodeRef, std::uint32_t> pixels;
        for (std::uint32_t id : partAt)
            if (id != 0) ++pixels[{partOfId[id - 1].object, partOfId[id - 1].node}];
        for (const auto& [key, n] : pixels) {
            ref.visible.parts.push_back(key);
            ref.visible.pixels.push_back(n);
            ref.visible.coveredPixels += n;
        }
        return ref;
    }
};

TEST(NearFar, NearPlane1eMinus4WithFarPlane1e7MatchesTheLayeredReference) {
    NearFarScene scene;
    ASSERT_TRUE(scene.rig.ok());
    const NearFarScene::Reference ref = scene.reference();
    const Rig::Result r = scene.rig.frame(camera(kNear, kFar));
    const VisibleSet truth = scene.rig.truth->compute(*scene.rig.engine, camera(kNear, kFar));

    auto vfcVsRef = compareImages(ref.image, r.vfcImage);
    auto fullImgVsRef = compareImages(ref.image, r.queriesImage);
    ASSERT_TRUE(vfcVsRef.ok() && fullImgVsRef.ok());
    const PartErrors truthVsRef = compareParts(ref.visible, truth.parts);
    const PartErrors fullPartsVsRef = compareParts(ref.visible, r.queriesDrawn);
    std::uint32_t hiddenDrawn = 0, hiddenObjects = 0;
    std::set<std::uint32_t> drawnObjects;
    for (const NodeRef& k : r.queriesDrawn) drawnObjects.insert(k.object);
    for (const auto& p : scene.placed)
        if (p.hidden) {
            ++hiddenObjects;
            hiddenDrawn += drawnObjects.count(p.handle.index) ? 1u : 0u;
        }
    std::printf("near 1e-4 far 1e7: vfc differs from the layered reference in %.4f%% of pixels (%llu), queries in "
                "%.4f%%; ID pass sees %zu parts, reference %zu (%u missing, %u extra); queries misses %u visible parts "
                "of the reference, queries/vfc parts drawn %u/%u, hidden objects drawn by queries %u of %u, queries "
                "occluded %u\n",
                vfcVsRef->percentDiffering, static_cast<unsigned long long>(vfcVsRef->differingPixels),
                fullImgVsRef->percentDiffering, truth.parts.size(), ref.visible.parts.size(), truthVsRef.falseNegatives,
                truthVsRef.falsePositives, fullPartsVsRef.falseNegatives, r.queriesStats.partsDrawn, r.vfcStats.partsDrawn,
                hiddenDrawn, hiddenObjects, r.queriesStats.queriesOccluded);

    // The scene is what it claims: every object not hidden by construction shows, no hidden one does.
    std::set<std::uint32_t> refObjects;
    for (const NodeRef& k : ref.visible.parts) refObjects.insert(k.object);
    for (const auto& p : scene.placed)
        EXPECT_EQ(refObjects.count(p.handle.index), p.hidden ? 0u : 1u) << p.what << " at layer " << p.layer;

    // Images as precise as the other extremes tests, the ID pass exact, full conservative
    // and culling what is hidden.
    EXPECT_LE(vfcVsRef->percentDiffering, 0.01);
    EXPECT_LE(fullImgVsRef->percentDiffering, 0.01);
    test::expectConservative(r, "near 1e-4 far 1e7");
    EXPECT_EQ(truthVsRef.falseNegatives + truthVsRef.falsePositives, 0u);
    EXPECT_EQ(truth.artefactPixels, 0u);  // every ID-pass fragment lies in its box's reversed-Z depth range
    EXPECT_EQ(fullPartsVsRef.falseNegatives, 0u);
    EXPECT_EQ(hiddenDrawn, 0u);
    EXPECT_LT(r.queriesStats.partsDrawn, r.vfcStats.partsDrawn);

    // full (two-phase): its depth pyramid and raster tests are as exact at these ranges.
    auto twoPhaseVsRef = compareImages(ref.image, r.fullImage);
    ASSERT_TRUE(twoPhaseVsRef.ok());
    EXPECT_LE(twoPhaseVsRef->percentDiffering, 0.01);
    EXPECT_EQ(compareParts(ref.visible, r.fullDrawn).falseNegatives, 0u);
    EXPECT_LT(r.fullStats.partsDrawn, r.vfcStats.partsDrawn);

    // Its raster tests are exact at these ranges: with the early set refreshed by them
    // (useRefreshPyramid off), full draws no hidden object. By default the refresh reads
    // the pyramid, whose slack (DepthPyramid::kDepthSlack, 2^-16 of the depth) keeps a quad
    // 1e-5 of its distance behind another in the early set once it was drawn: drawn, never
    // lost (the image and the parts are checked above).
    SchedulerParams exact = scene.rig.full.params();
    exact.features.useRefreshPyramid = false;
    QueryScheduler rasterRefresh(exact);
    for (int frame = 0; frame < 2; ++frame) {
        scene.rig.ctx->clearFramebuffer(Renderer::kClearColour);
        ASSERT_TRUE(scene.rig.engine->renderFrame(rasterRefresh).ok());
    }
    std::set<std::uint32_t> twoPhaseObjects;
    for (const NodeRef& k : drawnLeaves(scene.rig.engine->objects(), scene.rig.engine->visibleParts())) twoPhaseObjects.insert(k.object);
    for (const auto& p : scene.placed)
        if (p.hidden) {
            EXPECT_EQ(twoPhaseObjects.count(p.handle.index), 0u) << "full with the raster refresh drew hidden " << p.what;
        }
}

}  // namespace
}  // namespace dyncull
