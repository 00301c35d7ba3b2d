// Subdividing a model larger than memory into a streamed model (node file + geometry file),
// never holding the whole model: "Out-of-core interactive display of large meshes using an
// oriented bounding box-based hardware depth query", section 4 (a tree built under an
// available-memory parameter, geometry grouped per leaf in a separate file, an LRU cache of
// vertices), with dyncull's in-memory subdivision (Scene subdivision for occlusion culling,
// section 3) below the size that fits.
//
// Passes, each bounded in memory:
//  1. The source streams into temporary files: positions, normals, polygons.
//  2. Polygons are triangulated with positions from an LRU block cache of the position
//     file, and written as triangle records (positions and vertex ids); vertex normals are
//     accumulated in a write-back block cache when the source has none (or bad ones).
//  3. The records are split front to back: a node too large for the memory budget is cut
//     at the median centroid along its longest centroid extent (a histogram gathered
//     while its records were written) into two files; a node that fits is read, rebuilt as
//     a mesh and subdivided in memory with SubdivisionParams' method, and its leaves are
//     written as chunks.
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>

#include "dyncull/bsp/subdivision.hpp"
#include "dyncull/objects/error.hpp"
#include "dyncull/objects/mesh_stream.hpp"
#include "dyncull/streaming/streamed_model.hpp"

namespace dyncull {

struct OutOfCoreParams {
    /// The in-memory subdivision below the streamed splits; maxLeafTriangles and maxDepth
    /// hold for the whole tree (streamed splits count toward the depth).
    SubdivisionParams subdivision;
    /// Bytes the builder's own buffers may hold (caches, file buffers, the subtree built in
    /// memory); the process adds its code and the allocator's slack. At least 16 MiB.
    std::size_t memoryBytes = std::size_t{512} << 20;
    /// Where temporary files go (created, removed at the end, also on errors). Empty: a
    /// directory next to the node file. Needs about 100 bytes per triangle, twice at peak.
    std::filesystem::path tempDirectory;
    /// What the node file records as its source (a path or a built-in scene name).
    std::string source;
    std::uint64_t sourceHash = 0;
};

struct OutOfCoreStats {
    std::uint64_t vertices = 0;
    std::uint64_t polygons = 0;
    std::uint64_t triangles = 0;
    bool normalsFromSource = false;  ///< false: computed (the source had none, or bad ones)
    std::uint32_t nodes = 0;
    std::uint32_t leaves = 0;
    std::uint32_t streamedSplits = 0;    ///< nodes cut by streaming their records
    std::uint32_t memorySubtrees = 0;    ///< subtrees built in memory
    std::uint64_t largestSubtree = 0;    ///< triangles of the largest of them
    std::uint64_t subtreeLimit = 0;      ///< triangles the budget allows in memory at once
    std::uint64_t cacheLookups = 0;      ///< vertex lookups in the position and normal caches
    std::uint64_t cacheMisses = 0;       ///< of them, blocks read from disk
    std::uint64_t tempBytesWritten = 0;
    std::uint64_t tempBytesRead = 0;
    std::uint64_t geometryBytes = 0;
    double readMs = 0.0, triangulateMs = 0.0, buildMs = 0.0;
};

/// Reports progress: a phase name ("reading", "triangulating", "subdividing"), work done
/// and the phase's total, in the phase's units (bytes, polygons, triangles).
using OutOfCoreProgress = std::function<void(const char* phase, double done, double total)>;

/// A mesh source: streams the whole mesh into the sink once per call.
using MeshStreamSource = std::function<Status(MeshStreamSink&)>;

/// Builds `nodePath` (BASE.dnodes) and BASE.dgeom from `source`. Errors, never asserts:
/// parameters out of range, the source's own errors, a leaf over kMaxLeafChunkBytes, and
/// full disks; on error no output file is left behind. The result does not depend on the
/// budget where no streamed split is needed (a model that fits is subdivided whole).
Expected<OutOfCoreStats> subdivideOutOfCore(const MeshStreamSource& source, const std::filesystem::path& nodePath,
                                            const OutOfCoreParams& params, const OutOfCoreProgress& progress = {});

/// An in-memory mesh as a source (vertices, then triangles), for built-in scenes and tests.
MeshStreamSource meshSource(const Mesh& mesh);

}  // namespace dyncull
