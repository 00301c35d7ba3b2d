#include "dyncull/objects/checked_write.hpp"

#include <cerrno>
#include <cstdio>
#include <cstring>

namespace dyncull {
namespace {

Error writeError(const std::filesystem::path& path, const char* what, int err) {
    return Error{path.string() + ": " + what + (err ? std::string(": ") + std::strerror(err) : std::string()), ErrorCode::Io};
}

}  // namespace

Status writeFileChecked(const std::filesystem::path& path, std::string_view bytes) {
    errno = 0;
    std::FILE* f = std::fopen(path.c_str(), "wb");
    if (!f) return writeError(path, "cannot open for writing", errno);
    const std::size_t wrote = bytes.empty() ? 0 : std::fwrite(bytes.data(), 1, bytes.size(), f);
    const int writeErrno = errno;
    // fclose flushes the stdio buffer: a full device often shows only here.
    const bool flushed = std::fflush(f) == 0;
    const int flushErrno = errno;
    const bool closed = std::fclose(f) == 0;
    if (wrote != bytes.size()) return writeError(path, "write failed", writeErrno);
    if (!flushed) return writeError(path, "write failed", flushErrno);
    if (!closed) return writeError(path, "close failed", errno);
    return {};
}

Status openChecked(std::ofstream& stream, const std::filesystem::path& path) {
    errno = 0;
    stream.open(path, std::ios::out | std::ios::trunc);
    if (!stream) return writeError(path, "cannot open for writing", errno);
    return {};
}

Status flushChecked(std::ofstream& stream, const std::filesystem::path& path) {
    errno = 0;
    stream.flush();
    if (!stream) return writeError(path, "write failed", errno);
    return {};
}

Status closeChecked(std::ofstream& stream, const std::filesystem::path& path) {
    if (!stream.is_open()) return writeError(path, "write failed (file not open)", 0);
    errno = 0;
    stream.flush();
    const bool flushed = static_cast<bool>(stream);
    const int flushErrno = errno;
    stream.close();
    if (!flushed) return writeError(path, "write failed", flushErrno);
    if (stream.fail()) return writeError(path, "close failed", errno);
    return {};
}

}  // namespace dyncull
