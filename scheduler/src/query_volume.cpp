#include "dyncull/scheduler/query_backend.hpp"

namespace dyncull {

QueryVolume QueryVolume::fromAabb(const Aabb& box) {
    QueryVolume v;
    for (int i = 0; i < 8; ++i)
        v.corners[i] = {(i & 1) ? box.max.x : box.min.x, (i & 2) ? box.max.y : box.min.y,
                        (i & 4) ? box.max.z : box.min.z};
    return v;
}

QueryVolume QueryVolume::fromTransformedBox(const glm::mat4& objectToWorld, const Aabb& local) {
    QueryVolume v = fromAabb(local);
    for (glm::vec3& c : v.corners) c = glm::vec3(objectToWorld * glm::vec4(c, 1.0f));
    return v;
}

}  // namespace dyncull
