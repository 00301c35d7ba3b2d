// Streaming PLY: the one PLY parser and writer. loadPly collects what it reads into a mesh;
// out-of-core preprocessing (dyncull::streaming) reads models larger than memory through
// it, since the parser holds only a window of the file and one face at a time.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include <glm/vec3.hpp>

#include "dyncull/objects/error.hpp"
#include "dyncull/objects/mesh_stream.hpp"

namespace dyncull {

/// Parses `path` (ascii, binary_little_endian or binary_big_endian; every scalar type and
/// alias; other elements and properties skipped) into `sink` (borrowed), in file order.
/// Needs a `vertex` element with x, y, z (nx, ny, nz optional) and a `face` element with a
/// `vertex_indices` (or `vertex_index`) list. The file is mapped and read once, front to
/// back; pages already parsed are released, so resident memory stays a few megabytes
/// whatever the file's size. Errors name the path and, for data, the element and line
/// (ASCII) or index (binary); a sink's error comes back with the path in front.
Status streamPly(const std::filesystem::path& path, MeshStreamSink& sink);

}  // namespace dyncull

namespace dyncull {

/// Writes a binary little-endian PLY front to back without holding the mesh: the counts
/// go in the header first, then exactly that many vertices (x y z, and nx ny nz when
/// `normals`), then triangles (a uchar-counted int list). Written under a ".tmp" name and
/// renamed into place by close(), so a reader never sees half a file; every write and the
/// close are checked, and the error names the path.
class PlyWriter {
public:
    PlyWriter() = default;
    PlyWriter(const PlyWriter&) = delete;
    PlyWriter& operator=(const PlyWriter&) = delete;
    ~PlyWriter();

    Status open(const std::filesystem::path& path, std::uint64_t vertices, std::uint64_t triangles, bool normals,
                const std::string& comment = {});
    Status vertex(const glm::vec3& position, const glm::vec3& normal = glm::vec3(0.0f));
    /// Indices must be below the declared vertex count; vertices must all be written first.
    Status triangle(std::uint32_t a, std::uint32_t b, std::uint32_t c);
    /// Checks that the declared counts were written, then flushes, closes and renames.
    Status close();

private:
    Status put(const void* bytes, std::size_t size);
    Status flush();
    std::filesystem::path path_, tmp_;
    int fd_ = -1;
    bool normals_ = false;
    std::uint64_t vertices_ = 0, triangles_ = 0, verticesWritten_ = 0, trianglesWritten_ = 0;
    std::vector<unsigned char> buffer_;
};

}  // namespace dyncull
