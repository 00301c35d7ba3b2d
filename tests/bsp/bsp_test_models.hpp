// Hand-built local BSPs for the scene-level tests (no dependency on buildLocalBsp).
#pragma once

#include "dyncull/bsp/local_bsp.hpp"

namespace dyncull::test {

/// Single-leaf root over the unit cube [-0.5, 0.5]^3 (12 triangles, indices not needed).
inline LocalBsp cubeModel(float half = 0.5f) {
    LocalBsp bsp;
    LocalBspNode root;
    root.box = Aabb::fromMinMax(glm::vec3(-half), glm::vec3(half));
    root.indexCount = 36;
    bsp.nodes.push_back(root);
    return bsp;
}

/// Three nodes in DFS order: root [-1,1]^3 split at x = 0 into [-1,0] (node 1) and [0,1] (node 2).
inline LocalBsp twoHalvesModel() {
    LocalBsp bsp;
    LocalBspNode root, lo, hi;
    root.box = Aabb::fromMinMax(glm::vec3(-1.0f), glm::vec3(1.0f));
    root.children[0] = 1;
    root.children[1] = 2;
    root.indexCount = 72;
    root.subtreeSize = 3;
    root.axis = 0;
    root.split = 0.0f;
    lo.box = Aabb::fromMinMax(glm::vec3(-1.0f), glm::vec3(0.0f, 1.0f, 1.0f));
    lo.indexCount = 36;
    lo.depth = 1;
    hi.box = Aabb::fromMinMax(glm::vec3(0.0f, -1.0f, -1.0f), glm::vec3(1.0f));
    hi.firstIndex = 36;
    hi.indexCount = 36;
    hi.depth = 1;
    bsp.nodes = {root, lo, hi};
    return bsp;
}

}  // namespace dyncull::test
