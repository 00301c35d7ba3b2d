// The records of dyncull's own binary files (the subdivision file, the scene cache): one
// writer and one reader for both, so hashing, count prefixes and the bounds checks that
// keep a corrupt or hostile file from crashing or over-allocating live in one place.
// Little-endian host order, as both formats declare.
#pragma once

#include <algorithm>
#include <bit>
#include <cstdint>
#include <cstring>
#include <istream>
#include <ostream>
#include <string>
#include <type_traits>
#include <vector>

#include "dyncull/objects/checksum.hpp"

namespace dyncull {

static_assert(std::endian::native == std::endian::little, "dyncull's binary files are written in host (little-endian) order");

/// Streams records to `out` (borrowed), hashing every byte (FNV-1a 64) for the file's checksum.
class BinaryWriter {
public:
    explicit BinaryWriter(std::ostream& out) : out_(out) {}
    void bytes(const void* p, std::size_t n) {
        out_.write(static_cast<const char*>(p), static_cast<std::streamsize>(n));
        hash_ = fnv1a64(p, n, hash_);
        size_ += n;
    }
    template <class T>
    void put(const T& v) {
        static_assert(std::is_trivially_copyable_v<T>);
        bytes(&v, sizeof(T));
    }
    /// A count of type Count, then the elements.
    template <class Count, class T>
    void array(const std::vector<T>& v) {
        put(static_cast<Count>(v.size()));
        bytes(v.data(), v.size() * sizeof(T));
    }
    template <class Count>
    void str(const std::string& s) {
        put(static_cast<Count>(s.size()));
        bytes(s.data(), s.size());
    }
    std::uint64_t hash() const { return hash_; }
    std::uint64_t size() const { return size_; }

private:
    std::ostream& out_;
    std::uint64_t hash_ = kFnv1a64Seed;
    std::uint64_t size_ = 0;
};

/// Reads at most `size` bytes of records from `in` (borrowed). After the first failure
/// every read fails and yields zeros, so a parser checks once per record; a count larger
/// than the bytes left fails before anything is allocated.
class BinaryReader {
public:
    BinaryReader(std::istream& in, std::uint64_t size) : in_(in), left_(size) {}
    bool bytes(void* p, std::size_t n) {
        if (fail_ || n > left_) {
            fail_ = true;
            std::memset(p, 0, n);
            return false;
        }
        in_.read(static_cast<char*>(p), static_cast<std::streamsize>(n));
        if (!in_) {
            fail_ = true;
            return false;
        }
        left_ -= n;
        return true;
    }
    template <class T>
    T get() {
        T v{};
        bytes(&v, sizeof(T));
        return v;
    }
    template <class Count, class T>
    bool array(std::vector<T>& v) {
        const auto n = get<Count>();
        if (fail_ || n > left_ / sizeof(T)) return fail_ = true, false;
        v.resize(static_cast<std::size_t>(n));
        return bytes(v.data(), v.size() * sizeof(T));
    }
    template <class Count>
    bool str(std::string& s, std::uint32_t maxLength) {
        const auto n = get<Count>();
        if (fail_ || n > left_ || n > maxLength) return fail_ = true, false;
        s.resize(static_cast<std::size_t>(n));
        return bytes(s.data(), s.size());
    }
    bool failed() const { return fail_; }
    std::uint64_t left() const { return left_; }

private:
    std::istream& in_;
    std::uint64_t left_;
    bool fail_ = false;
};

/// Hashes the next `payload` bytes of `in` in 1 MiB chunks (no copy of a large file) and
/// compares with `expected`: "" if equal, else why not ("read failed", "checksum mismatch (corrupt)").
inline std::string checkPayload(std::istream& in, std::uint64_t payload, std::uint64_t expected) {
    std::vector<char> chunk(std::size_t{1} << 20);
    std::uint64_t hash = kFnv1a64Seed, left = payload;
    while (left > 0) {
        const auto n = static_cast<std::size_t>(std::min<std::uint64_t>(left, chunk.size()));
        in.read(chunk.data(), static_cast<std::streamsize>(n));
        if (!in) return "read failed";
        hash = fnv1a64(chunk.data(), n, hash);
        left -= n;
    }
    return hash == expected ? std::string() : std::string("checksum mismatch (corrupt)");
}

}  // namespace dyncull
