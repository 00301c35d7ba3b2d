// Temporary record files of out-of-core preprocessing: buffered sequential writers and
// readers with every write checked, and an LRU cache of fixed-size blocks of a file of
// per-vertex records (the paper's vertex cache), optionally write-back. Private.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "dyncull/objects/error.hpp"

namespace dyncull::detail {

/// A directory removed with everything in it when this object dies.
class TempDirectory {
public:
    static Expected<TempDirectory> create(const std::filesystem::path& parent, const std::string& stem);
    TempDirectory(TempDirectory&& o) noexcept : path_(std::move(o.path_)) { o.path_.clear(); }
    TempDirectory& operator=(TempDirectory&&) = delete;
    ~TempDirectory();
    const std::filesystem::path& path() const { return path_; }

private:
    explicit TempDirectory(std::filesystem::path p) : path_(std::move(p)) {}
    std::filesystem::path path_;
};

/// Appends bytes to a new file through a buffer of `bufferBytes`.
class RecordWriter {
public:
    RecordWriter() = default;
    RecordWriter(const RecordWriter&) = delete;
    RecordWriter& operator=(const RecordWriter&) = delete;
    ~RecordWriter();
    Status open(const std::filesystem::path& path, std::size_t bufferBytes);
    Status write(const void* bytes, std::size_t size);
    /// Flushes and closes, checking both; the writer can be opened again.
    Status close();
    std::uint64_t written() const { return written_; }

private:
    Status flush();
    std::filesystem::path path_;
    int fd_ = -1;
    std::vector<unsigned char> buffer_;
    std::size_t used_ = 0;
    std::uint64_t written_ = 0;
};

/// Reads a file front to back through a buffer of `bufferBytes`.
class RecordReader {
public:
    RecordReader() = default;
    RecordReader(const RecordReader&) = delete;
    RecordReader& operator=(const RecordReader&) = delete;
    ~RecordReader();
    Status open(const std::filesystem::path& path, std::size_t bufferBytes);
    /// Reads exactly `size` bytes; false at the end of the file (or a short record, an error
    /// the caller reports: our own temporary files never have one).
    bool read(void* bytes, std::size_t size);
    std::uint64_t bytesRead() const { return read_; }

private:
    std::filesystem::path path_;
    int fd_ = -1;
    std::vector<unsigned char> buffer_;
    std::size_t at_ = 0, size_ = 0;
    std::uint64_t offset_ = 0, read_ = 0;
};

/// An LRU cache of blocks of a file holding `count` records of `RecordBytes` each, indexed
/// by record. Write-back mode (`writable`) keeps modified blocks until evicted or flush().
template <class Record>
class BlockCache {
public:
    static constexpr std::uint32_t kBlockRecords = 8192;
    BlockCache() = default;
    BlockCache(const BlockCache&) = delete;
    BlockCache& operator=(const BlockCache&) = delete;
    ~BlockCache();
    /// Opens `path` (which must hold `count` records) with room for `cacheBytes` of blocks
    /// (at least 2 blocks).
    Status open(const std::filesystem::path& path, std::uint64_t count, std::size_t cacheBytes, bool writable);
    /// The record `i` (< count); valid until the next call. Errors are read/write failures.
    Expected<Record*> at(std::uint64_t i);
    Status flush();
    void close();
    std::uint64_t lookups() const { return lookups_; }
    std::uint64_t misses() const { return misses_; }
    std::uint64_t bytesRead() const { return bytesRead_; }
    std::uint64_t bytesWritten() const { return bytesWritten_; }

private:
    struct Slot {
        std::uint64_t block = UINT64_MAX;
        std::uint64_t used = 0;  // lookup clock of the last use
        bool dirty = false;
    };
    Status writeBack(std::size_t slot);
    std::filesystem::path path_;
    int fd_ = -1;
    bool writable_ = false;
    std::uint64_t count_ = 0;
    std::vector<Record> data_;            // slots x kBlockRecords
    std::vector<Slot> slots_;
    std::vector<std::uint32_t> slotOf_;   // per block: its slot + 1, 0 if not cached
    std::uint64_t lookups_ = 0, misses_ = 0, bytesRead_ = 0, bytesWritten_ = 0;
    std::size_t lastSlot_ = 0;
};

}  // namespace dyncull::detail
