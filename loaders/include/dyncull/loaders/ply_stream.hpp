// Streaming PLY: the one PLY parser. loadPly collects what it reads into a mesh;
// out-of-core preprocessing (dyncull::streaming) reads models larger than memory through
// it, since the parser holds only a window of the file and one face at a time.
#pragma once

#include <filesystem>

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
