// The scheduler's view of an occlusion-query implementation. The core never includes
// OpenGL: engine/ provides the GL backend (GL_ANY_SAMPLES_PASSED_CONSERVATIVE or
// GL_SAMPLES_PASSED with a threshold); tests provide scripted and software backends.
#pragma once

#include <array>
#include <cstdint>

#include <glm/glm.hpp>

#include "dyncull/objects/aabb.hpp"
#include "dyncull/objects/camera.hpp"

namespace dyncull {

/// Three states: a query either answered or has not answered yet. Nothing blocks on
/// NotReady while other work is possible.
enum class QueryResult : std::uint8_t { NotReady, Visible, Occluded };

/// A convex query volume: a box given by its 8 world-space corners; corner i has
/// x from bit 0, y from bit 1, z from bit 2 (so an AABB or a transformed local box —
/// a parallelepiped — both fit). Drawn with colour and depth writes off.
struct QueryVolume {
    std::array<glm::vec3, 8> corners;

    static QueryVolume fromAabb(const Aabb& box);
    /// The object-space box `local` under the affine `objectToWorld` (exact, not re-bounded).
    static QueryVolume fromTransformedBox(const glm::mat4& objectToWorld, const Aabb& local);
};

using QueryId = std::uint32_t;

class QueryBackend {
public:
    virtual ~QueryBackend() = default;

    /// Start of a frame: the camera whose view-projection query volumes are drawn with
    /// (world space) and the viewport in pixels.
    virtual void beginFrame(const Camera& camera, int width, int height) = 0;
    /// Brackets a group of queries issued together, so state (colour/depth masks,
    /// the volume shader) is switched once per batch rather than once per query.
    virtual void beginBatch() = 0;
    virtual QueryId issue(const QueryVolume& volume) = 0;
    virtual void endBatch() = 0;
    /// Non-blocking.
    virtual QueryResult poll(QueryId id) = 0;
    /// Blocks until the result is available or `timeoutMs` passed; a result that never
    /// arrives within the bound is reported Visible (never cull, never stall forever).
    virtual QueryResult wait(QueryId id, double timeoutMs) = 0;
    /// Returns the query object to the backend's pool. Every issued id is released once.
    virtual void release(QueryId id) = 0;
    /// Number of samples that passed for an answered query (0 if unknown). Used by
    /// threshold settings and statistics.
    virtual std::uint64_t samples(QueryId) const { return 0; }
};

/// What the scheduler calls to draw an object part: slot `object` of SceneObjects, the
/// index range [firstIndex, firstIndex + indexCount) of its model's split mesh.
class PartSink {
public:
    virtual ~PartSink() = default;
    virtual void drawPart(std::uint32_t object, std::uint32_t firstIndex, std::uint32_t indexCount) = 0;
};

}  // namespace dyncull
