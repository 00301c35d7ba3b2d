// A mesh as a stream of vertices and polygons, for models larger than memory: the
// streaming PLY parser (dyncull::loaders, streamPly) writes into a MeshStreamSink, and
// out-of-core preprocessing (dyncull::streaming) reads from it, without a whole Mesh
// ever existing.
#pragma once

#include <cstdint>
#include <span>

#include <glm/vec3.hpp>

#include "dyncull/objects/error.hpp"

namespace dyncull {

/// What a stream declares before any data, handed to MeshStreamSink::begin.
struct MeshStreamLayout {
    std::uint64_t vertices = 0;  ///< < 2^32 (indices are 32-bit)
    std::uint64_t faces = 0;     ///< declared; polygons with fewer than 3 corners are not passed on
    bool normals = false;        ///< vertices carry normals
    /// Polygons come before the vertices they index (a PLY file whose face element comes
    /// first), so a sink cannot look positions up as faces arrive.
    bool facesFirst = false;
    std::uint64_t bytes = 0;  ///< size of what is streamed (a file's size), for progress
};

/// Receives a mesh in stream order. Returning an error stops the stream; the source
/// passes it on with its own context (a file's path) in front.
class MeshStreamSink {
public:
    virtual ~MeshStreamSink() = default;
    virtual Status begin(const MeshStreamLayout& layout) = 0;
    /// The next vertex (source units). The position is finite (checked by the source);
    /// `normal` is zero when the source has none, and as stored (not normalised, maybe
    /// zero) otherwise.
    virtual Status vertex(const glm::vec3& position, const glm::vec3& normal) = 0;
    /// The next polygon: 3 or more corners, each < layout.vertices (checked by the
    /// source). Valid during the call only. Not triangulated: that needs positions,
    /// which a streaming source does not hold.
    virtual Status face(std::span<const std::uint32_t> corners) = 0;
    /// Bytes of layout.bytes streamed so far, for progress; called every few megabytes.
    virtual void progress(std::uint64_t /*bytesDone*/) {}
};

}  // namespace dyncull
