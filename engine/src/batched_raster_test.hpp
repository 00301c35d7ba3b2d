// Internal: the batched raster test behind GlQueryBackend::testVolumes.
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include <glm/glm.hpp>

#include "dyncull/objects/error.hpp"
#include "dyncull/scheduler/query_backend.hpp"
#include "volume_raster.hpp"

namespace dyncull {
class GlContext;
}

namespace dyncull::detail {

/// Owns a vertex and an index stream for the volumes, a program whose fragments mark
/// `visible[volume]` in a storage buffer (and one that counts them there), and one such
/// buffer per batch in flight. Needs
/// the GL context current for its whole life. Knows nothing of when a batch is answered:
/// GlQueryBackend brackets each draw with a query and reads a batch once it has answered.
class BatchedRasterTest {
public:
    static Expected<std::unique_ptr<BatchedRasterTest>> create(GlContext& context);
    ~BatchedRasterTest();
    BatchedRasterTest(const BatchedRasterTest&) = delete;
    BatchedRasterTest& operator=(const BatchedRasterTest&) = delete;

    /// Draws every volume of `volumes` (world space) in one call with `viewProjRelative`
    /// (Camera::viewProjectionRelative) against the bound framebuffer's depth, inside
    /// `state`. A volume reaching the near plane is marked visible without being drawn.
    /// On a failed allocation nothing is drawn and every volume is marked visible (the
    /// error goes to the context's log). With `count`, each volume's passing fragments
    /// are counted, not just marked. Returns the batch to read.
    BatchId draw(std::span<const QueryVolume> volumes, const VolumeView& view, const glm::mat4& viewProjRelative,
                 VolumeTestState& state, bool count = false);
    /// The answers of a drawn batch (waits for the draw if it has not finished), one per
    /// volume in order, and frees the batch. `samples` (empty, or one per volume): the
    /// counts of a counted batch, kUnknownSamples where unknown (see QueryBackend::collectVolumes).
    void read(BatchId id, std::span<QueryResult> out, std::span<std::uint32_t> samples = {});
    /// Frees a batch without reading it.
    void discard(BatchId id);
    std::uint32_t volumeCount(BatchId id) const { return batches_[id].count; }
    /// Whether the batch's draw was issued (else every answer is known already).
    bool drawn(BatchId id) const { return batches_[id].drawn; }

private:
    explicit BatchedRasterTest(GlContext& context) : context_(context) {}
    bool allocate(std::uint32_t buffer, std::size_t bytes, const char* what);

    struct Vertex {
        glm::vec3 position;  // relative to the eye
        std::uint32_t volume;  // index in the batch
    };
    struct Batch {
        std::uint32_t buffer = 0;    // GL storage buffer: one uint per volume, 0 = hidden
        std::uint32_t capacity = 0;  // volumes the buffer holds
        std::uint32_t count = 0;
        std::vector<std::uint8_t> visibleUndrawn;  // answered Visible without drawing
        bool drawn = false;  // the draw was issued: `buffer` holds answers
        bool counted = false;  // `buffer` holds sample counts, not marks
        bool live = false;
    };
    GlContext& context_;
    std::uint32_t program_ = 0, countProgram_ = 0, vao_ = 0, vbo_ = 0, ibo_ = 0;
    int locViewProj_ = -1, locCountViewProj_ = -1;
    std::vector<Batch> batches_;
    std::vector<BatchId> free_;
    // Reused per draw.
    std::vector<Vertex> vertices_;
    std::vector<std::uint32_t> indices_;
    std::vector<std::uint32_t> readback_;
};

}  // namespace dyncull::detail
