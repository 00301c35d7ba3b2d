// Temporary files of out-of-core preprocessing (temp_files.hpp): checked buffered I/O and
// the LRU block cache of per-vertex records.
#include "temp_files.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <random>

#include <glm/vec3.hpp>

#include "geometry_chunk.hpp"

namespace dyncull::detail {
namespace {

Error ioError(const std::filesystem::path& path, const char* what) {
    return Error{"temporary file " + path.string() + ": " + what + ": " + std::strerror(errno), ErrorCode::Io};
}

}  // namespace

Expected<TempDirectory> TempDirectory::create(const std::filesystem::path& parent, const std::string& stem) {
    std::error_code ec;
    std::filesystem::create_directories(parent, ec);
    std::random_device rd;
    for (int attempt = 0; attempt < 16; ++attempt) {
        const auto p = parent / (stem + ".tmp" + std::to_string(rd() % 1000000));
        if (std::filesystem::create_directory(p, ec)) return TempDirectory(p);
    }
    return Error{"cannot create a temporary directory in " + parent.string() + (ec ? ": " + ec.message() : ""), ErrorCode::Io};
}

TempDirectory::~TempDirectory() {
    if (path_.empty()) return;
    std::error_code ec;
    std::filesystem::remove_all(path_, ec);
}

RecordWriter::~RecordWriter() {
    if (fd_ >= 0) ::close(fd_);
}

Status RecordWriter::open(const std::filesystem::path& path, std::size_t bufferBytes) {
    path_ = path;
    fd_ = ::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0600);
    if (fd_ < 0) return ioError(path, "cannot create");
    buffer_.resize(std::max<std::size_t>(bufferBytes, 4096));
    used_ = 0;
    written_ = 0;
    return {};
}

Status RecordWriter::flush() {
    if (used_ == 0) return {};
    if (!writeAllAt(fd_, buffer_.data(), used_, written_ - used_)) return ioError(path_, "write failed");
    used_ = 0;
    return {};
}

Status RecordWriter::write(const void* bytes, std::size_t size) {
    const auto* p = static_cast<const unsigned char*>(bytes);
    while (size > 0) {
        if (used_ == buffer_.size())
            if (Status s = flush(); !s) return s;
        const std::size_t n = std::min(size, buffer_.size() - used_);
        std::memcpy(buffer_.data() + used_, p, n);
        used_ += n;
        written_ += n;
        p += n;
        size -= n;
    }
    return {};
}

Status RecordWriter::close() {
    Status s = flush();
    if (fd_ >= 0 && ::close(fd_) != 0 && s) s = ioError(path_, "close failed");
    fd_ = -1;
    std::vector<unsigned char>().swap(buffer_);
    return s;
}

RecordReader::~RecordReader() {
    if (fd_ >= 0) ::close(fd_);
}

Status RecordReader::open(const std::filesystem::path& path, std::size_t bufferBytes) {
    path_ = path;
    fd_ = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
    if (fd_ < 0) return ioError(path, "cannot open");
    ::posix_fadvise(fd_, 0, 0, POSIX_FADV_SEQUENTIAL);
    buffer_.resize(std::max<std::size_t>(bufferBytes, 4096));
    at_ = size_ = 0;
    offset_ = read_ = 0;
    return {};
}

bool RecordReader::read(void* bytes, std::size_t size) {
    auto* p = static_cast<unsigned char*>(bytes);
    while (size > 0) {
        if (at_ == size_) {
            ssize_t n;
            do n = ::pread(fd_, buffer_.data(), buffer_.size(), static_cast<off_t>(offset_));
            while (n < 0 && errno == EINTR);
            if (n <= 0) return false;
            offset_ += static_cast<std::uint64_t>(n);
            at_ = 0;
            size_ = static_cast<std::size_t>(n);
        }
        const std::size_t n = std::min(size, size_ - at_);
        std::memcpy(p, buffer_.data() + at_, n);
        at_ += n;
        p += n;
        size -= n;
        read_ += n;
    }
    return true;
}

template <class Record>
BlockCache<Record>::~BlockCache() {
    close();
}

template <class Record>
void BlockCache<Record>::close() {
    if (fd_ >= 0) ::close(fd_);
    fd_ = -1;
    std::vector<Record>().swap(data_);
    std::vector<Slot>().swap(slots_);
    std::vector<std::uint32_t>().swap(slotOf_);
}

template <class Record>
Status BlockCache<Record>::open(const std::filesystem::path& path, std::uint64_t count, std::size_t cacheBytes,
                                bool writable) {
    close();
    path_ = path;
    writable_ = writable;
    count_ = count;
    fd_ = ::open(path.c_str(), (writable ? O_RDWR : O_RDONLY) | O_CLOEXEC);
    if (fd_ < 0) return ioError(path, "cannot open");
    const std::uint64_t blocks = (count + kBlockRecords - 1) / kBlockRecords;
    const std::size_t blockBytes = sizeof(Record) * kBlockRecords;
    const std::size_t slots = static_cast<std::size_t>(
        std::max<std::uint64_t>(2, std::min<std::uint64_t>(blocks, cacheBytes / blockBytes)));
    data_.resize(slots * kBlockRecords);
    slots_.assign(slots, Slot{});
    slotOf_.assign(static_cast<std::size_t>(blocks), 0);
    lookups_ = misses_ = bytesRead_ = bytesWritten_ = 0;
    return {};
}

template <class Record>
Status BlockCache<Record>::writeBack(std::size_t slot) {
    Slot& s = slots_[slot];
    if (!s.dirty) return {};
    const std::uint64_t first = s.block * kBlockRecords;
    const std::uint64_t n = std::min<std::uint64_t>(kBlockRecords, count_ - first);
    if (!writeAllAt(fd_, &data_[slot * kBlockRecords], static_cast<std::size_t>(n * sizeof(Record)), first * sizeof(Record)))
        return ioError(path_, "write failed");
    bytesWritten_ += n * sizeof(Record);
    s.dirty = false;
    return {};
}

template <class Record>
Expected<Record*> BlockCache<Record>::at(std::uint64_t i) {
    const std::uint64_t block = i / kBlockRecords;
    ++lookups_;
    std::size_t slot;
    if (slotOf_[block] != 0) {
        slot = slotOf_[block] - 1;
    } else {
        ++misses_;
        // The least recently used slot; a linear scan, as slots are few (tens to hundreds).
        slot = 0;
        for (std::size_t k = 1; k < slots_.size(); ++k)
            if (slots_[k].used < slots_[slot].used) slot = k;
        if (Status s = writeBack(slot); !s) return s.error();
        if (slots_[slot].block != UINT64_MAX) slotOf_[slots_[slot].block] = 0;
        const std::uint64_t first = block * kBlockRecords;
        const std::uint64_t n = std::min<std::uint64_t>(kBlockRecords, count_ - first);
        if (!readAllAt(fd_, &data_[slot * kBlockRecords], static_cast<std::size_t>(n * sizeof(Record)), first * sizeof(Record)))
            return ioError(path_, "read failed");
        bytesRead_ += n * sizeof(Record);
        slots_[slot].block = block;
        slotOf_[block] = static_cast<std::uint32_t>(slot + 1);
    }
    slots_[slot].used = lookups_;
    if (writable_) slots_[slot].dirty = true;
    return &data_[slot * kBlockRecords + (i - block * kBlockRecords)];
}

template <class Record>
Status BlockCache<Record>::flush() {
    for (std::size_t k = 0; k < slots_.size(); ++k)
        if (Status s = writeBack(k); !s) return s;
    return {};
}

template class BlockCache<glm::vec3>;

}  // namespace dyncull::detail
