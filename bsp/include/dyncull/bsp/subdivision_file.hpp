// Subdivided static model on disk (`dyncull subdivide ... --out FILE.dsub`), loaded by
// `dyncull run/bench FILE.dsub`. The file is untrusted input: the header, size and checksum
// are verified before any content is parsed, every count is checked against the bytes
// left, and the mesh and tree are validated (validateSubdivision) before anything is
// returned.
//
// Layout (little-endian): a 48-byte header
//   magic "DYNCSUB\0" | u32 format version | u32 header size (48) | u64 source hash |
//   u64 payload size | u64 FNV-1a 64 of the payload | u64 reserved (0)
// then the payload: source (u32 length + bytes), parameters, mesh (name, positions,
// normals, indices in leaf order; u64 counts), nodes (u64 count, 44 bytes each), stats.
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>

#include "dyncull/bsp/subdivision.hpp"
#include "dyncull/objects/binary_file.hpp"
#include "dyncull/objects/error.hpp"
#include "dyncull/objects/mesh.hpp"
#include "dyncull/objects/surface_orientation.hpp"

namespace dyncull {

inline constexpr std::uint32_t kSubdivisionFileVersion = 1;
inline constexpr std::size_t kSubdivisionFileHeaderSize = 48;

/// A subdivided model: owns the mesh (triangles in leaf order) and its subdivision
/// (sub.triangles empty), plus what it was made from.
struct SubdividedModel {
    Mesh mesh;  ///< mesh space = world space of the objects made from it
    Subdivision subdivision;
    SubdivisionParams params;  ///< as used (threads is not stored; reads give the default)
    /// What was subdivided: a built-in scene name ("powerplant", "city") or a model path.
    /// Decides the camera path of `dyncull run` on the file.
    std::string source;
    /// Generator parameter hash of a built-in source (0 for files): a run with other
    /// generator options would fly another camera path, so readers can refuse it.
    std::uint64_t sourceHash = 0;
    /// The mesh's surface as orientSurface left it, when this process oriented it
    /// (subdivideStaticScene); a model read from a file has none, and is analysed.
    std::optional<SurfaceReport> surface;
};

/// The subdivision parameters (threads excepted) and tree nodes as records of dyncull's
/// binary files: the .dsub file here and a streamed model's node file (streaming/) share
/// these, so both read and write them one way.
void writeSubdivisionParams(BinaryWriter& w, const SubdivisionParams& p);
/// Reads what writeSubdivisionParams wrote: "" or why not (truncated, unknown method,
/// a parameter out of range).
std::string readSubdivisionParams(BinaryReader& r, SubdivisionParams& p);
inline constexpr std::size_t kSubdivisionNodeBytes = 44;  ///< a node record
void writeSubdivisionNode(BinaryWriter& w, const SubdivisionNode& n);
/// A node record, unchecked (the readers validate the whole tree); zeros after a failure.
SubdivisionNode readSubdivisionNode(BinaryReader& r);

/// Writes via a temporary file renamed into place (readers never see half a file).
/// Errors name the path. `model.subdivision.triangles` must be empty (applyTriangleOrder).
Status writeSubdivisionFile(const std::filesystem::path& path, const SubdividedModel& model);

/// Reads and validates. The one-line error names the path and why: cannot open, bad magic,
/// other format version, truncated or padded, checksum mismatch, or malformed content.
Expected<SubdividedModel> readSubdivisionFile(const std::filesystem::path& path);

}  // namespace dyncull
