// The geometry file's chunk and header encoding (layout in streamed_model.hpp), shared by
// the writer (node_file.cpp) and the reader (geometry_file.cpp). Private.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "dyncull/streaming/streamed_model.hpp"

namespace dyncull::detail {

inline constexpr char kGeometryMagic[8] = {'D', 'Y', 'N', 'C', 'G', 'E', 'O', '\0'};
inline constexpr std::size_t kChunkHeaderBytes = 16;

/// Appends `g`'s chunk to `out` (cleared first). "" or why it cannot be encoded.
std::string encodeChunk(const Mesh& g, std::vector<unsigned char>& out);

/// The 48-byte geometry file header.
void encodeGeometryHeader(std::uint64_t geometryId, std::uint64_t fileBytes, unsigned char out[kStreamedHeaderSize]);

/// Writes all of `bytes` at `offset` of `fd`, retrying short writes. false with errno set.
bool writeAllAt(int fd, const void* bytes, std::size_t size, std::uint64_t offset);
/// Reads all of `bytes` at `offset` of `fd`. false on error or end of file.
bool readAllAt(int fd, void* bytes, std::size_t size, std::uint64_t offset);

}  // namespace dyncull::detail
