#include <cmath>
#include <limits>

#include <gtest/gtest.h>

#include "bsp_test_models.hpp"
#include "dyncull/bsp/scene_objects.hpp"
#include "objects/transform_at.hpp"

using namespace dyncull;

namespace {

using test::at;

}  // namespace

TEST(SceneObjects, AddComputesMatrixAndWorldBox) {
    SceneObjects so;
    const ModelId m = so.addModel(test::cubeModel());
    Transform t = at({10.0f, 0.0f, 0.0f}, 2.0f);
    auto h = so.addObject(m, t);
    ASSERT_TRUE(h.ok());
    EXPECT_EQ(so.objectCount(), 1u);
    const Aabb& b = so.worldBox(h->index);
    EXPECT_FLOAT_EQ(b.min.x, 9.0f);
    EXPECT_FLOAT_EQ(b.max.x, 11.0f);
    EXPECT_FLOAT_EQ(b.max.y, 1.0f);
    EXPECT_EQ(so.added().size(), 1u);
    EXPECT_TRUE(so.moved().empty());
}

TEST(SceneObjects, UnknownModelAndBadTransformAreErrors) {
    SceneObjects so;
    auto bad = so.addObject(3, Transform{});
    ASSERT_FALSE(bad.ok());
    EXPECT_NE(bad.error().message.find("unknown model"), std::string::npos);
    const ModelId m = so.addModel(test::cubeModel());
    Transform nanT = at({std::nanf(""), 0, 0});
    EXPECT_FALSE(so.addObject(m, nanT).ok());
    Transform zero = at({0, 0, 0}, 0.0f);
    EXPECT_FALSE(so.addObject(m, zero).ok());
    EXPECT_EQ(so.objectCount(), 0u);
    EXPECT_EQ(so.slotCount(), 0u);  // nothing half-added
}

TEST(SceneObjects, SetTransformMarksMovedOnceAndRejectsBadInputWithoutChange) {
    SceneObjects so;
    const ModelId m = so.addModel(test::cubeModel());
    ObjectHandle h = so.addObject(m, at({0, 0, 0})).take();
    ASSERT_TRUE(so.setTransform(h, at({1, 0, 0})).ok());
    ASSERT_TRUE(so.setTransform(h, at({2, 0, 0})).ok());
    EXPECT_EQ(so.moved().size(), 1u);
    EXPECT_FLOAT_EQ(so.worldBox(h.index).center().x, 2.0f);
    Transform inf = at({0, 0, 0}, std::numeric_limits<float>::infinity());
    Status s = so.setTransform(h, inf);
    EXPECT_FALSE(s.ok());
    EXPECT_NE(s.message().find("setTransform"), std::string::npos);
    EXPECT_FLOAT_EQ(so.worldBox(h.index).center().x, 2.0f);  // unchanged
    Transform huge = at({3e38f, 0, 0}, 1e38f);  // finite inputs, box max overflows float
    EXPECT_FALSE(so.setTransform(h, huge).ok());
    so.clearMoved();
    EXPECT_TRUE(so.moved().empty());
    ASSERT_TRUE(so.setTransform(h, at({3, 0, 0})).ok());
    EXPECT_EQ(so.moved().size(), 1u);
}

TEST(SceneObjects, StaleHandlesAreDetectedAndSlotsReusedWithNewGeneration) {
    SceneObjects so;
    const ModelId m = so.addModel(test::cubeModel());
    ObjectHandle a = so.addObject(m, at({0, 0, 0})).take();
    ObjectHandle b = so.addObject(m, at({5, 0, 0})).take();
    ASSERT_TRUE(so.removeObject(a).ok());
    EXPECT_FALSE(so.alive(a));
    EXPECT_TRUE(so.alive(b));
    EXPECT_FALSE(so.removeObject(a).ok());
    Status s = so.setTransform(a, at({1, 1, 1}));
    EXPECT_FALSE(s.ok());
    EXPECT_NE(s.message().find("stale"), std::string::npos);
    ObjectHandle c = so.addObject(m, at({7, 0, 0})).take();
    EXPECT_EQ(c.index, a.index);  // slot reused from the free list
    EXPECT_EQ(c.generation, a.generation + 1);
    EXPECT_FALSE(so.alive(a));  // old handle stays stale after reuse
    EXPECT_TRUE(so.alive(c));
    EXPECT_EQ(so.objectCount(), 2u);
    EXPECT_EQ(so.slotCount(), 2u);
    EXPECT_EQ(so.removed().size(), 1u);
    EXPECT_EQ(so.added().size(), 3u);
    EXPECT_FALSE(so.removeObject(ObjectHandle{}).ok());
    EXPECT_FALSE(so.removeObject(ObjectHandle{99, 0}).ok());
}

// A static object promises never to move: setTransform refuses it and leaves it as it was.
TEST(SceneObjects, StaticObjectsRefuseToMove) {
    SceneObjects so;
    const ModelId m = so.addModel(test::cubeModel());
    const ObjectHandle s = so.addObject(m, at({1, 2, 3}), true).take();
    const ObjectHandle d = so.addObject(m, at({0, 0, 0})).take();
    so.clearMoved();
    const Status st = so.setTransform(s, at({5, 5, 5}));
    ASSERT_FALSE(st.ok());
    EXPECT_EQ(st.code(), ErrorCode::BadArgument);
    EXPECT_NE(st.message().find("static"), std::string::npos) << st.message();
    EXPECT_EQ(so.transform(s.index).translation, glm::vec3(1, 2, 3));
    EXPECT_TRUE(so.moved().empty());
    EXPECT_TRUE(so.setTransform(d, at({5, 5, 5})).ok());
}

// placedAt changes with every placement and with the reuse of a slot, never otherwise.
TEST(SceneObjects, PlacementSerialsMarkMovesAndSlotReuse) {
    SceneObjects so;
    const ModelId m = so.addModel(test::cubeModel());
    const ObjectHandle a = so.addObject(m, at({0, 0, 0})).take();
    const ObjectHandle b = so.addObject(m, at({1, 0, 0})).take();
    const std::uint64_t a0 = so.placedAt(a.index), b0 = so.placedAt(b.index);
    EXPECT_NE(a0, b0);
    ASSERT_TRUE(so.setTransform(a, at({0, 1, 0})).ok());
    EXPECT_GT(so.placedAt(a.index), b0);
    EXPECT_EQ(so.placedAt(b.index), b0);
    const std::uint64_t a1 = so.placedAt(a.index);
    ASSERT_FALSE(so.setTransform(a, at({std::nanf(""), 0, 0})).ok());  // refused: no new placement
    EXPECT_EQ(so.placedAt(a.index), a1);
    ASSERT_TRUE(so.removeObject(b).ok());
    const ObjectHandle c = so.addObject(m, at({1, 0, 0})).take();  // same slot, same place, new object
    ASSERT_EQ(c.index, b.index);
    EXPECT_NE(so.placedAt(c.index), b0);
}

// A model in use cannot be removed; a removed model's id stays refused; setModel moves an
// object to another model under a new handle, keeping its transform and static flag.
TEST(SceneObjects, ModelsAreRemovedOnlyWhenUnusedAndObjectsChangeModel) {
    SceneObjects so;
    const ModelId small = so.addModel(test::cubeModel(0.5f));
    const ModelId big = so.addModel(test::cubeModel(2.0f));
    const ObjectHandle h = so.addObject(small, at({1, 2, 3}), true).take();
    const Status inUse = so.removeModel(small);
    ASSERT_FALSE(inUse.ok());
    EXPECT_NE(inUse.message().find("used by 1"), std::string::npos) << inUse.message();

    auto moved = so.setModel(h, big);
    ASSERT_TRUE(moved.ok()) << moved.error().message;
    EXPECT_FALSE(so.alive(h));  // the old handle is stale
    ASSERT_TRUE(so.alive(*moved));
    EXPECT_EQ(so.modelOf(moved->index), big);
    EXPECT_EQ(so.transform(moved->index).translation, glm::vec3(1, 2, 3));
    EXPECT_TRUE(so.isStatic(moved->index));
    EXPECT_FLOAT_EQ(so.worldBox(moved->index).max.x - so.worldBox(moved->index).min.x, 4.0f);

    ASSERT_TRUE(so.removeModel(small).ok());
    EXPECT_FALSE(so.modelAlive(small));
    EXPECT_FALSE(so.removeModel(small).ok());
    EXPECT_FALSE(so.addObject(small, at({0, 0, 0})).ok());
    EXPECT_FALSE(so.setModel(*moved, small).ok());
    EXPECT_FALSE(so.setModel(h, big).ok());
    EXPECT_EQ(so.modelCount(), 2u);  // ids are not reused
    EXPECT_EQ(so.model(small).nodes.size(), 1u);
}
