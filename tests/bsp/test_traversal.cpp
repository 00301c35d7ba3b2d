#include <algorithm>
#include <random>

#include <glm/gtc/quaternion.hpp>
#include <gtest/gtest.h>

#include "bsp_test_models.hpp"
#include "dyncull/bsp/traversal.hpp"
#include "objects/transform_at.hpp"

using namespace dyncull;

namespace {

using test::at;

bool refLess(const NodeRef& a, const NodeRef& b) {
    return a.object != b.object ? a.object < b.object : a.node < b.node;
}

// 300 objects, half single-leaf cubes and half two-leaf models, random rotations.
struct World {
    SceneObjects so;
    LooseBsp bsp;
    World() {
        const ModelId cube = so.addModel(test::cubeModel());
        const ModelId halves = so.addModel(test::twoHalvesModel());
        std::mt19937 rng(42);
        std::uniform_real_distribution<float> u(-60.0f, 60.0f), a(0.0f, 6.28f);
        for (int i = 0; i < 300; ++i) {
            const glm::quat r = glm::angleAxis(a(rng), glm::normalize(glm::vec3(u(rng), u(rng), u(rng)) + glm::vec3(0.01f)));
            so.addObject(i % 2 ? halves : cube, at({u(rng), u(rng) * 0.3f, u(rng)}, 1.0f + float(i % 4), r)).take();
        }
        bsp.build(so);
    }
};

}  // namespace

TEST(Traversal, SceneNodeExpandsNearChildObjectsSortedThenFarChild) {
    World w;
    TwoLevelTree tree(w.bsp, w.so);
    std::mt19937 rng(3);
    std::uniform_real_distribution<float> u(-80.0f, 80.0f);
    std::vector<NodeRef> out;
    int checkedInner = 0;
    for (std::uint32_t n = 0; n < w.bsp.nodes().size(); ++n) {
        const LooseBspNode& node = w.bsp.nodes()[n];
        if (node.subtreeObjects == 0) continue;
        const glm::vec3 eye(u(rng), u(rng), u(rng));
        out.clear();
        tree.expand({kInvalidIndex, n}, eye, out);
        std::size_t objBegin = 0, objEnd = out.size();
        if (!node.isLeaf()) {
            const std::uint32_t nearC = eye[node.axis] > node.split ? node.children[1] : node.children[0];
            const std::uint32_t farC = nearC == node.children[0] ? node.children[1] : node.children[0];
            if (w.bsp.nodes()[nearC].subtreeObjects > 0) {
                ASSERT_EQ(out.front(), (NodeRef{kInvalidIndex, nearC}));
                objBegin = 1;
            }
            if (w.bsp.nodes()[farC].subtreeObjects > 0) {
                ASSERT_EQ(out.back(), (NodeRef{kInvalidIndex, farC}));
                objEnd = out.size() - 1;
            }
            ++checkedInner;
        }
        ASSERT_EQ(objEnd - objBegin, node.objectCount);
        float last = -1.0f;
        for (std::size_t k = objBegin; k < objEnd; ++k) {
            ASSERT_FALSE(out[k].isSceneNode());
            ASSERT_EQ(out[k].node, 0u);
            const float d = glm::length(w.so.worldBox(out[k].object).center() - eye);
            EXPECT_GE(d, last);
            last = d;
        }
    }
    EXPECT_GT(checkedInner, 10);
}

TEST(Traversal, LocalNearChildUsesEyeInObjectSpace) {
    SceneObjects so;
    const ModelId halves = so.addModel(test::twoHalvesModel());
    // Rotated 180 degrees about y: object +x points to world -x.
    const ObjectHandle h = so.addObject(halves, at({10.0f, 0.0f, 0.0f}, 2.0f, glm::angleAxis(3.14159265f, glm::vec3(0, 1, 0)))).take();
    LooseBsp bsp;
    bsp.build(so);
    TwoLevelTree tree(bsp, so);
    std::vector<NodeRef> out;
    tree.expand({h.index, 0}, {20.0f, 0.0f, 0.0f}, out);  // eye at world +x = object -x side
    ASSERT_EQ(out.size(), 2u);
    EXPECT_EQ(out[0], (NodeRef{h.index, 1}));
    EXPECT_EQ(out[1], (NodeRef{h.index, 2}));
    out.clear();
    tree.expand({h.index, 0}, {0.0f, 0.0f, 0.0f}, out);
    EXPECT_EQ(out[0], (NodeRef{h.index, 2}));
    EXPECT_TRUE(tree.isDrawable({h.index, 1}));
    EXPECT_FALSE(tree.isDrawable({h.index, 0}));
    EXPECT_FALSE(tree.isDrawable(tree.root()));
    // World box of a local node: the node box under the object's matrix.
    const Aabb b = tree.worldBox({h.index, 2});  // object x in [0,1] -> world x in [8,10]
    EXPECT_NEAR(b.min.x, 8.0f, 1e-4f);
    EXPECT_NEAR(b.max.x, 10.0f, 1e-4f);
}

TEST(Traversal, FrustumDescentMatchesBruteForce) {
    World w;
    TwoLevelTree tree(w.bsp, w.so);
    std::mt19937 rng(8);
    std::uniform_real_distribution<float> u(-90.0f, 90.0f);
    std::size_t totalVisible = 0;
    for (int c = 0; c < 20; ++c) {
        Camera cam;
        cam.position = {u(rng), u(rng) * 0.2f, u(rng)};
        cam.target = {u(rng) * 0.5f, 0.0f, u(rng) * 0.5f};
        cam.farPlane = 60.0f + float(c) * 5.0f;
        const Frustum fr = Frustum::fromMatrix(cam.viewProjection());
        std::vector<NodeRef> got;
        FrontToBackIterator it(tree, cam.position);
        NodeRef ref;
        while (it.next(ref)) {
            if (fr.outside(tree.worldBox(ref))) continue;
            if (tree.isDrawable(ref)) got.push_back(ref);
            else it.descend();
        }
        std::vector<NodeRef> want = frustumLeavesBruteForce(w.so, fr);
        std::sort(got.begin(), got.end(), refLess);
        std::sort(want.begin(), want.end(), refLess);
        EXPECT_EQ(got, want) << "camera " << c;
        totalVisible += want.size();
    }
    EXPECT_GT(totalVisible, 100u);  // the cameras actually see things
}

TEST(Traversal, FullDescentVisitsEveryLeafOnceFrontToBackAtObjectLevel) {
    World w;
    TwoLevelTree tree(w.bsp, w.so);
    const glm::vec3 eye(5.0f, 2.0f, -7.0f);
    FrontToBackIterator it(tree, eye);
    NodeRef ref;
    std::vector<NodeRef> leaves;
    std::vector<std::uint32_t> sceneOrder;
    while (it.next(ref)) {
        if (ref.isSceneNode()) sceneOrder.push_back(ref.node);
        if (tree.isDrawable(ref)) leaves.push_back(ref);
        else it.descend();
    }
    EXPECT_EQ(sceneOrder.size(), std::count_if(w.bsp.nodes().begin(), w.bsp.nodes().end(),
                                               [](const LooseBspNode& n) { return n.subtreeObjects > 0; }) +
                                     0u);
    // 150 cubes (1 leaf) + 150 two-leaf models.
    EXPECT_EQ(leaves.size(), 450u);
    std::sort(leaves.begin(), leaves.end(), refLess);
    EXPECT_EQ(std::adjacent_find(leaves.begin(), leaves.end()), leaves.end());
    // The leaf containing the eye's scene cell is visited before its sibling.
    const auto& root = w.bsp.nodes()[0];
    const std::uint32_t nearC = eye[root.axis] > root.split ? root.children[1] : root.children[0];
    const auto posNear = std::find(sceneOrder.begin(), sceneOrder.end(), nearC);
    const auto posFar = std::find(sceneOrder.begin(), sceneOrder.end(), nearC == root.children[0] ? root.children[1] : root.children[0]);
    EXPECT_LT(posNear, posFar);
}

TEST(Traversal, EmptySceneYieldsNothing) {
    SceneObjects so;
    LooseBsp bsp;
    bsp.build(so);
    TwoLevelTree tree(bsp, so);
    FrontToBackIterator it(tree, glm::vec3(0.0f));
    NodeRef ref;
    EXPECT_FALSE(it.next(ref));
    Camera cam;
    EXPECT_TRUE(frustumLeavesBruteForce(so, Frustum::fromMatrix(cam.viewProjection())).empty());
}
