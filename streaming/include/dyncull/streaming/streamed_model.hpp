// A model larger than memory, on disk as two files, as in "Out-of-core interactive display
// of large meshes using an oriented bounding box-based hardware depth query", section 4:
//   BASE.dnodes  the node file: the subdivision tree, each leaf's volumes and where its
//                geometry lies. Small; read whole and checked when the model is opened.
//   BASE.dgeom   the geometry file: one chunk per leaf (vertices, normals, triangles),
//                read one leaf at a time when the leaf is needed, and checked then.
// Both are untrusted input: every count, offset and size is checked with overflow-safe
// arithmetic before use, and a bad leaf is an error naming the file and the leaf.
//
// Node file (little-endian): 48-byte header
//   magic "DYNCNOD\0" | u32 version | u32 header size (48) | u64 reserved (0) |
//   u64 payload size | u64 FNV-1a 64 of the payload | u64 geometry id
// then the payload: source (u32 length + bytes), u64 source hash, subdivision parameters, geometry file
// size, nodes (u32 count, 44 bytes each as in the subdivision file), leaves (u32 count,
// 120 bytes each: node, counts, chunk size, offset, checksum, box, PCA box).
// Geometry file: 48-byte header
//   magic "DYNCGEO\0" | u32 version | u32 header size (48) | u64 geometry id |
//   u64 file size | u64 reserved (0) x 2
// then the chunks, each: u32 vertices | u32 triangles | u32 index bytes (2 or 4) |
//   u32 reserved (0) | positions (3 f32 each) | unit normals (3 f32 each) | indices,
//   padded with zeros to a multiple of 4 bytes.
#pragma once

#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include <glm/vec3.hpp>

#include "dyncull/bsp/subdivision.hpp"
#include "dyncull/objects/aabb.hpp"
#include "dyncull/objects/error.hpp"
#include "dyncull/objects/mesh.hpp"
#include "dyncull/objects/obb.hpp"

namespace dyncull {

inline constexpr std::uint32_t kStreamedModelVersion = 1;
inline constexpr std::size_t kStreamedHeaderSize = 48;
/// Largest chunk a reader accepts: a leaf is meant to be loaded whole and fast.
inline constexpr std::uint32_t kMaxLeafChunkBytes = 256u << 20;

/// Main-memory bytes of a leaf's geometry as read (positions, normals, indices): what the
/// streaming budgets count.
std::size_t leafBytes(const Mesh& leaf);
struct StreamedLeaf;
/// The same, known from the node file before the leaf is read.
std::size_t leafBytes(const StreamedLeaf& leaf);

/// Where a leaf's geometry is, and the volumes the scheduler tests before loading it.
struct StreamedLeaf {
    std::uint32_t node = 0;  ///< its node in StreamedModel::nodes
    std::uint32_t vertexCount = 0;
    std::uint32_t triangleCount = 0;
    std::uint32_t chunkBytes = 0;  ///< size of its chunk in the geometry file
    std::uint64_t offset = 0;      ///< of its chunk, from the start of the geometry file
    std::uint64_t checksum = 0;    ///< FNV-1a 64 of the chunk
    Aabb box;  ///< of its vertices, model space; equals its node's box
    Obb obb;   ///< PCA box of its vertices (fitObbPca), model space
};

/// The node file's contents. Owns everything; the geometry stays on disk.
struct StreamedModel {
    /// What was subdivided: a built-in scene name or a model path (as in SubdividedModel).
    std::string source;
    std::uint64_t sourceHash = 0;
    /// Parameters of the in-memory subdivision below the streamed splits (threads not stored).
    SubdivisionParams params;
    /// The tree, in the layout of Subdivision::nodes: children contiguous and after their
    /// parent; firstTriangle/triangleCount count triangles in leaf order.
    std::vector<SubdivisionNode> nodes;
    /// One per non-empty leaf node, in leaf order (ascending firstTriangle).
    std::vector<StreamedLeaf> leaves;
    std::uint64_t geometryId = 0;     ///< written into both files; a mismatched pair is refused
    std::uint64_t geometryBytes = 0;  ///< the geometry file's size
    std::filesystem::path nodePath, geometryPath;  ///< set by readStreamedModel

    std::uint64_t triangles() const { return nodes.empty() ? 0 : nodes[0].triangleCount; }
    std::uint32_t largestChunk() const;
};

/// BASE.dgeom for BASE.dnodes (the extension replaced, whatever it was).
std::filesystem::path geometryPathFor(const std::filesystem::path& nodePath);

/// Writes a streamed model: leaves first, as they are made, then the tree. Both files are
/// written under a ".tmp" name and renamed into place by finish(), so readers never see
/// half a model; a writer destroyed before finish() removes its temporary files.
class StreamedModelWriter {
public:
    /// Creates BASE.dgeom.tmp for `nodePath` = BASE.dnodes. The error names the file.
    static Expected<StreamedModelWriter> create(const std::filesystem::path& nodePath);
    StreamedModelWriter(StreamedModelWriter&&) noexcept;
    StreamedModelWriter& operator=(StreamedModelWriter&&) noexcept;
    ~StreamedModelWriter();

    /// Appends one leaf's chunk (written at once; `geometry` is not kept) for tree node
    /// `node`, with its box and PCA box computed from the positions. Returns the leaf's
    /// index. Errors: empty or malformed geometry, more than 2^32-1 of anything, a chunk
    /// above kMaxLeafChunkBytes, a failed write.
    /// `geometry`: the leaf in its own compact vertex numbering, model space, one unit
    /// normal per vertex.
    Expected<std::uint32_t> addLeaf(const Mesh& geometry, std::uint32_t node);
    const std::vector<StreamedLeaf>& leaves() const;
    std::uint64_t geometryBytes() const;

    /// Writes the node file from `model` (source, params and nodes; its leaves and
    /// geometry fields are filled from this writer), checks both files' writes and closes,
    /// and renames them into place. The tree is validated first (as a reader would).
    Status finish(StreamedModel& model);

private:
    struct State;
    explicit StreamedModelWriter(std::unique_ptr<State> s);
    std::unique_ptr<State> s_;
};

/// Reads and validates the node file and checks that its geometry file is there, of the
/// right size and with the same geometry id. Does not read any chunk.
Expected<StreamedModel> readStreamedModel(const std::filesystem::path& nodePath);

/// Reads leaves from a model's geometry file. Thread-safe: reads are positioned (pread),
/// so a loader thread and the render thread may read at once.
struct CompactLeaf;

class GeometryFile {
public:
    /// Opens model.geometryPath (borrowing nothing: the leaf table is copied).
    static Expected<GeometryFile> open(const StreamedModel& model);
    GeometryFile(GeometryFile&&) noexcept;
    GeometryFile& operator=(GeometryFile&&) noexcept;
    ~GeometryFile();

    /// Reads leaf `leaf` into `out` (its vectors reused). The chunk's checksum, counts,
    /// index range, finite values and containment in the leaf's box are checked; the
    /// error names the file and the leaf. `scratch` holds the raw chunk between calls.
    /// `out` gets positions, unit normals and indices (model space; its name is left alone).
    Status read(std::uint32_t leaf, Mesh& out, std::vector<unsigned char>& scratch) const;
    /// Reads leaf `leaf` as every reader that shows it takes it (compact_leaf.hpp): checked
    /// by read() into `decoded`, then quantised in the leaf's box into `out`. `decoded` and
    /// `scratch` are the caller's to reuse.
    Status readCompact(std::uint32_t leaf, CompactLeaf& out, Mesh& decoded, std::vector<unsigned char>& scratch) const;
    std::uint32_t leafCount() const;

private:
    struct State;
    explicit GeometryFile(std::unique_ptr<State> s);
    std::unique_ptr<State> s_;
};

}  // namespace dyncull
