// Binary PLY writer (ply_stream.hpp): a model streamed to disk in one pass, e.g. a
// procedural scene exported for out-of-core preprocessing.
#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <bit>
#include <cstring>

#include "dyncull/loaders/ply_stream.hpp"
#include "loader_common.hpp"

namespace dyncull {
namespace {

static_assert(std::endian::native == std::endian::little, "records are copied as little-endian");
constexpr std::size_t kBuffer = std::size_t{4} << 20;

}  // namespace

PlyWriter::~PlyWriter() {
    if (fd_ >= 0) {
        ::close(fd_);
        std::error_code ec;
        std::filesystem::remove(tmp_, ec);  // never closed: an abandoned file
    }
}

Status PlyWriter::open(const std::filesystem::path& path, std::uint64_t vertices, std::uint64_t triangles, bool normals,
                       const std::string& comment) {
    if (vertices > 0xFFFFFFFFull) return Error{path.string() + ": more than 2^32 - 1 vertices", ErrorCode::BadArgument};
    path_ = path;
    tmp_ = path;
    tmp_ += ".tmp";
    fd_ = ::open(tmp_.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
    if (fd_ < 0) return Error{tmp_.string() + ": cannot create: " + std::strerror(errno), ErrorCode::Io};
    normals_ = normals;
    vertices_ = vertices;
    triangles_ = triangles;
    verticesWritten_ = trianglesWritten_ = 0;
    buffer_.clear();
    buffer_.reserve(kBuffer);
    std::string h = "ply\nformat binary_little_endian 1.0\n";
    if (!comment.empty()) h += "comment " + comment + "\n";
    h += "element vertex " + std::to_string(vertices) + "\nproperty float x\nproperty float y\nproperty float z\n";
    if (normals) h += "property float nx\nproperty float ny\nproperty float nz\n";
    h += "element face " + std::to_string(triangles) + "\nproperty list uchar int vertex_indices\nend_header\n";
    return put(h.data(), h.size());
}

Status PlyWriter::flush() {
    const unsigned char* p = buffer_.data();
    std::size_t left = buffer_.size();
    while (left > 0) {
        const ssize_t n = ::write(fd_, p, left);
        if (n < 0 && errno == EINTR) continue;
        if (n <= 0) return Error{tmp_.string() + ": write failed: " + std::strerror(errno), ErrorCode::Io};
        p += n;
        left -= static_cast<std::size_t>(n);
    }
    buffer_.clear();
    return {};
}

Status PlyWriter::put(const void* bytes, std::size_t size) {
    if (buffer_.size() + size > kBuffer)
        if (Status s = flush(); !s) return s;
    const auto* b = static_cast<const unsigned char*>(bytes);
    buffer_.insert(buffer_.end(), b, b + size);
    return {};
}

Status PlyWriter::vertex(const glm::vec3& position, const glm::vec3& normal) {
    if (verticesWritten_ == vertices_) return Error{path_.string() + ": more vertices than declared", ErrorCode::BadArgument};
    ++verticesWritten_;
    float v[6] = {position.x, position.y, position.z, normal.x, normal.y, normal.z};
    return put(v, normals_ ? 24 : 12);
}

Status PlyWriter::triangle(std::uint32_t a, std::uint32_t b, std::uint32_t c) {
    if (verticesWritten_ != vertices_) return Error{path_.string() + ": a triangle before every vertex", ErrorCode::BadArgument};
    if (trianglesWritten_ == triangles_) return Error{path_.string() + ": more triangles than declared", ErrorCode::BadArgument};
    if (a >= vertices_ || b >= vertices_ || c >= vertices_)
        return Error{path_.string() + ": triangle index out of range", ErrorCode::BadArgument};
    ++trianglesWritten_;
    unsigned char rec[13];
    rec[0] = 3;
    const std::int32_t idx[3] = {static_cast<std::int32_t>(a), static_cast<std::int32_t>(b), static_cast<std::int32_t>(c)};
    std::memcpy(rec + 1, idx, 12);  // little-endian host (binary_file.hpp asserts it)
    return put(rec, sizeof rec);
}

Status PlyWriter::close() {
    if (verticesWritten_ != vertices_ || trianglesWritten_ != triangles_)
        return Error{path_.string() + ": " + std::to_string(verticesWritten_) + " vertices and " +
                         std::to_string(trianglesWritten_) + " triangles written, the header declares " +
                         std::to_string(vertices_) + " and " + std::to_string(triangles_),
                     ErrorCode::BadArgument};
    if (Status s = flush(); !s) return s;
    const int fd = fd_;
    fd_ = -1;
    if (::close(fd) != 0) return Error{tmp_.string() + ": write failed on close: " + std::strerror(errno), ErrorCode::Io};
    std::error_code ec;
    std::filesystem::rename(tmp_, path_, ec);
    if (ec) return Error{path_.string() + ": cannot rename into place: " + ec.message(), ErrorCode::Io};
    return {};
}

}  // namespace dyncull
