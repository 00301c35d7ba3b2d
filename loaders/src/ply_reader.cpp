// PLY parser (Greg Turk's Stanford polygon format): ascii, binary_little_endian and
// binary_big_endian, all scalar types and their aliases, arbitrary extra elements and
// properties skipped. Our own parser over a read-only mapping of the file: numbers are
// parsed with std::from_chars in place (the 3 MB ASCII bunny parses in milliseconds), and
// pages behind the parser are dropped as it goes, so a file larger than memory streams.
#include "dyncull/loaders/ply_stream.hpp"

#include <fcntl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include <bit>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <exception>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "checked_math.hpp"
#include "loader_common.hpp"

namespace dyncull {
namespace {

/// A file mapped read-only. Parsers read it front to back and call release() with their
/// position: whole pages before it are dropped from the resident set (they are clean
/// file pages, so the kernel just forgets them).
class MappedFile {
public:
    MappedFile() = default;
    MappedFile(const MappedFile&) = delete;
    MappedFile& operator=(const MappedFile&) = delete;
    ~MappedFile() {
        if (data_) ::munmap(const_cast<char*>(data_), size_);
        if (fd_ >= 0) ::close(fd_);
    }
    Status open(const std::filesystem::path& path) {
        if (Status s = detail::checkFile(path); !s) return s;
        fd_ = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
        if (fd_ < 0) return detail::fileError(path, std::string("cannot open: ") + std::strerror(errno));
        struct stat st {};
        if (::fstat(fd_, &st) != 0 || st.st_size <= 0) return detail::fileError(path, "cannot read file size");
        size_ = static_cast<std::size_t>(st.st_size);
        void* p = ::mmap(nullptr, size_, PROT_READ, MAP_PRIVATE, fd_, 0);
        if (p == MAP_FAILED) return detail::fileError(path, std::string("cannot map: ") + std::strerror(errno));
        data_ = static_cast<const char*>(p);
        ::madvise(p, size_, MADV_SEQUENTIAL);
        return {};
    }
    std::string_view view() const { return {data_, size_}; }
    /// Drops the pages wholly before `upTo` (a pointer into view()) once 8 MiB have
    /// gathered, so the calls are cheap enough to make per element.
    void release(const char* upTo) {
        const auto done = static_cast<std::size_t>(upTo - data_);
        if (done < released_ + kReleaseStep) return;
        const std::size_t page = static_cast<std::size_t>(::sysconf(_SC_PAGESIZE));
        const std::size_t end = done / page * page;
        ::madvise(const_cast<char*>(data_) + released_, end - released_, MADV_DONTNEED);
        released_ = end;
    }

private:
    static constexpr std::size_t kReleaseStep = std::size_t{8} << 20;
    int fd_ = -1;
    const char* data_ = nullptr;
    std::size_t size_ = 0;
    std::size_t released_ = 0;
};

enum class Type : std::uint8_t { I8, U8, I16, U16, I32, U32, F32, F64 };

std::optional<Type> parseType(std::string_view s) {
    if (s == "char" || s == "int8") return Type::I8;
    if (s == "uchar" || s == "uint8") return Type::U8;
    if (s == "short" || s == "int16") return Type::I16;
    if (s == "ushort" || s == "uint16") return Type::U16;
    if (s == "int" || s == "int32") return Type::I32;
    if (s == "uint" || s == "uint32") return Type::U32;
    if (s == "float" || s == "float32") return Type::F32;
    if (s == "double" || s == "float64") return Type::F64;
    return std::nullopt;
}

std::size_t typeSize(Type t) {
    switch (t) {
        case Type::I8: case Type::U8: return 1;
        case Type::I16: case Type::U16: return 2;
        case Type::I32: case Type::U32: case Type::F32: return 4;
        case Type::F64: return 8;
    }
    return 0;
}

bool isFloat(Type t) { return t == Type::F32 || t == Type::F64; }

// What the loader does with a property.
enum class Role : std::uint8_t { Skip, X, Y, Z, NX, NY, NZ, Indices };

struct Property {
    std::string name;
    Type type = Type::F32;
    bool isList = false;
    Type countType = Type::U8;
    Role role = Role::Skip;
};

struct Element {
    std::string name;
    std::uint64_t count = 0;
    std::vector<Property> props;
};

enum class Format { Ascii, BinaryLE, BinaryBE };

// A parse failure: message without the path prefix (added by the caller).
struct Fail {
    std::string what;
};

std::string_view trimCR(std::string_view line) {
    while (!line.empty() && (line.back() == '\r' || line.back() == ' ' || line.back() == '\t')) line.remove_suffix(1);
    return line;
}

std::vector<std::string_view> splitWords(std::string_view line) {
    std::vector<std::string_view> words;
    std::size_t i = 0;
    while (i < line.size()) {
        while (i < line.size() && (line[i] == ' ' || line[i] == '\t')) ++i;
        const std::size_t start = i;
        while (i < line.size() && line[i] != ' ' && line[i] != '\t') ++i;
        if (i > start) words.push_back(line.substr(start, i - start));
    }
    return words;
}

struct Header {
    Format format = Format::Ascii;
    std::vector<Element> elements;
    std::size_t dataOffset = 0;  // first byte after "end_header\n"
    std::size_t lines = 0;       // header line count, for ASCII line numbers
};

std::optional<Fail> parseHeader(std::string_view data, Header& h) {
    std::size_t pos = 0;
    bool sawFormat = false;
    auto nextLine = [&](std::string_view& line) {
        if (pos >= data.size()) return false;
        std::size_t end = data.find('\n', pos);
        if (end == std::string_view::npos) end = data.size();
        line = trimCR(data.substr(pos, end - pos));
        pos = end + 1;
        ++h.lines;
        return true;
    };
    std::string_view line;
    if (!nextLine(line) || line != "ply") return Fail{"not a PLY file (first line is not 'ply')"};
    for (;;) {
        if (!nextLine(line)) return Fail{"header has no end_header line"};
        const auto w = splitWords(line);
        if (w.empty() || w[0] == "comment" || w[0] == "obj_info") continue;
        const std::string lineNo = "header line " + std::to_string(h.lines) + ": ";
        if (w[0] == "end_header") break;
        if (w[0] == "format") {
            if (w.size() < 3) return Fail{lineNo + "malformed format line"};
            if (w[1] == "ascii") h.format = Format::Ascii;
            else if (w[1] == "binary_little_endian") h.format = Format::BinaryLE;
            else if (w[1] == "binary_big_endian") h.format = Format::BinaryBE;
            else return Fail{lineNo + "unknown format '" + std::string(w[1]) + "'"};
            if (w[2] != "1.0") return Fail{lineNo + "unsupported PLY version '" + std::string(w[2]) + "'"};
            sawFormat = true;
        } else if (w[0] == "element") {
            if (w.size() != 3) return Fail{lineNo + "malformed element line"};
            Element e;
            e.name = std::string(w[1]);
            const auto r = std::from_chars(w[2].data(), w[2].data() + w[2].size(), e.count);
            if (r.ec != std::errc{} || r.ptr != w[2].data() + w[2].size())
                return Fail{lineNo + "bad element count '" + std::string(w[2]) + "'"};
            h.elements.push_back(std::move(e));
        } else if (w[0] == "property") {
            if (h.elements.empty()) return Fail{lineNo + "property before any element"};
            Property p;
            if (w.size() == 5 && w[1] == "list") {
                const auto ct = parseType(w[2]);
                const auto it = parseType(w[3]);
                if (!ct || !it) return Fail{lineNo + "unknown property type"};
                if (isFloat(*ct)) return Fail{lineNo + "list count type must be an integer type"};
                p.isList = true;
                p.countType = *ct;
                p.type = *it;
                p.name = std::string(w[4]);
            } else if (w.size() == 3) {
                const auto t = parseType(w[1]);
                if (!t) return Fail{lineNo + "unknown property type '" + std::string(w[1]) + "'"};
                p.type = *t;
                p.name = std::string(w[2]);
            } else {
                return Fail{lineNo + "malformed property line"};
            }
            h.elements.back().props.push_back(std::move(p));
        } else {
            return Fail{lineNo + "unknown header keyword '" + std::string(w[0]) + "'"};
        }
    }
    if (!sawFormat) return Fail{"header has no format line"};
    h.dataOffset = pos > data.size() ? data.size() : pos;
    return std::nullopt;
}

// Reads binary scalars of any type in either byte order.
struct BinaryReader {
    const unsigned char* p;
    const unsigned char* end;
    bool swap;

    bool has(std::size_t n) const { return static_cast<std::size_t>(end - p) >= n; }

    template <class T>
    T raw() {
        unsigned char b[sizeof(T)];
        std::memcpy(b, p, sizeof(T));
        if (swap)
            for (std::size_t i = 0; i < sizeof(T) / 2; ++i) std::swap(b[i], b[sizeof(T) - 1 - i]);
        p += sizeof(T);
        T v;
        std::memcpy(&v, b, sizeof(T));
        return v;
    }
    // Callers check has(typeSize(t)) first.
    double number(Type t) {
        switch (t) {
            case Type::I8: return raw<std::int8_t>();
            case Type::U8: return raw<std::uint8_t>();
            case Type::I16: return raw<std::int16_t>();
            case Type::U16: return raw<std::uint16_t>();
            case Type::I32: return raw<std::int32_t>();
            case Type::U32: return raw<std::uint32_t>();
            case Type::F32: return raw<float>();
            case Type::F64: return raw<double>();
        }
        return 0.0;
    }
    std::int64_t integer(Type t) {
        switch (t) {
            case Type::I8: return raw<std::int8_t>();
            case Type::U8: return raw<std::uint8_t>();
            case Type::I16: return raw<std::int16_t>();
            case Type::U16: return raw<std::uint16_t>();
            case Type::I32: return raw<std::int32_t>();
            case Type::U32: return raw<std::uint32_t>();
            case Type::F32: return static_cast<std::int64_t>(raw<float>());
            case Type::F64: return static_cast<std::int64_t>(raw<double>());
        }
        return 0;
    }
};

// Reads ASCII values token by token within the current line (each element instance is
// one line, which turns a missing or short line into a clear error).
struct AsciiReader {
    const char* p;
    const char* end;
    std::size_t line;  // 1-based number of the current line
    const char* lineEnd = nullptr;

    // Moves to the next non-blank line; false at end of file.
    bool nextLine() {
        if (lineEnd) {
            p = lineEnd < end ? lineEnd + 1 : end;
            ++line;
        }
        for (;;) {
            if (p >= end) return false;
            const char* nl = static_cast<const char*>(std::memchr(p, '\n', static_cast<std::size_t>(end - p)));
            lineEnd = nl ? nl : end;
            const char* q = p;
            while (q < lineEnd && (*q == ' ' || *q == '\t' || *q == '\r')) ++q;
            if (q < lineEnd) {
                p = q;
                return true;
            }
            p = lineEnd < end ? lineEnd + 1 : end;
            ++line;
        }
    }
    bool skipBlanks() {
        while (p < lineEnd && (*p == ' ' || *p == '\t' || *p == '\r')) ++p;
        return p < lineEnd;
    }
    bool atLineEnd() { return !skipBlanks(); }

    template <class T>
    bool value(T& out) {
        if (!skipBlanks()) return false;
        const char* s = p;
        if (*s == '+') ++s;  // from_chars rejects a leading '+'
        const auto r = std::from_chars(s, lineEnd, out);
        if (r.ec != std::errc{} || (r.ptr < lineEnd && *r.ptr != ' ' && *r.ptr != '\t' && *r.ptr != '\r'))
            return false;
        p = r.ptr;
        return true;
    }
    bool number(Type t, double& out) {
        if (isFloat(t)) return value(out);
        std::int64_t i = 0;
        if (!value(i)) return false;
        out = static_cast<double>(i);
        return true;
    }
    bool integer(std::int64_t& out) { return value(out); }
};

// The parse's state: the sink, the vertex being assembled, the corner list of the face
// being read, and the file window to release behind the parser.
struct Parse {
    Parse(MeshStreamSink& s, MappedFile& f, const Element& v) : sink(s), file(f), vertex(&v), vertexCount(v.count) {}
    MeshStreamSink& sink;
    MappedFile& file;
    const Element* vertex;
    std::uint64_t vertexCount;
    std::uint64_t verticesRead = 0;
    glm::vec3 position{0.0f}, normal{0.0f};
    std::vector<std::uint32_t> face;
};

std::string elementWhere(const Element& e, std::uint64_t i) { return e.name + " " + std::to_string(i); }

// Stores a parsed vertex property into the vertex being read.
void storeVertexValue(Parse& d, Role role, double value) {
    const float f = static_cast<float>(value);
    switch (role) {
        case Role::X: d.position.x = f; break;
        case Role::Y: d.position.y = f; break;
        case Role::Z: d.position.z = f; break;
        case Role::NX: d.normal.x = f; break;
        case Role::NY: d.normal.y = f; break;
        case Role::NZ: d.normal.z = f; break;
        default: break;
    }
}

// Called after each element instance: a complete vertex goes to the sink; `at` is the
// parser's position, behind which the file may be released.
std::optional<Fail> endInstance(Parse& d, const Element& e, const char* at) {
    d.file.release(at);
    if (&e != d.vertex) return std::nullopt;
    const glm::vec3& p = d.position;
    if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z))
        return Fail{"vertex " + std::to_string(d.verticesRead) + " has a non-finite coordinate"};
    if ((d.verticesRead & 0xFFFFF) == 0) d.sink.progress(static_cast<std::uint64_t>(at - d.file.view().data()));
    ++d.verticesRead;
    if (Status s = d.sink.vertex(d.position, d.normal); !s) return Fail{s.message()};
    d.position = d.normal = glm::vec3(0.0f);
    return std::nullopt;
}

// Hands a polygon to the sink after checking its indices against the vertex count.
// Faces with fewer than 3 corners are not surfaces: dropped on purpose. `where` is a
// callable giving the location (built only on error, it allocates).
template <class Where>
std::optional<Fail> addFace(Parse& d, const std::int64_t* idx, std::size_t n, const Where& where) {
    for (std::size_t k = 0; k < n; ++k)
        if (idx[k] < 0 || static_cast<std::uint64_t>(idx[k]) >= d.vertexCount)
            return Fail{where() + ": vertex index " + std::to_string(idx[k]) + " out of range (" +
                        std::to_string(d.vertexCount) + " vertices)"};
    if (n < 3) return std::nullopt;
    if (n > 0xFFFFFFFFu) return Fail{where() + ": face with more than 2^32 - 1 corners"};  // ASCII list counts are 64-bit
    d.face.clear();
    for (std::size_t k = 0; k < n; ++k) d.face.push_back(static_cast<std::uint32_t>(idx[k]));  // < vertexCount < 2^32
    if (Status s = d.sink.face(d.face); !s) return Fail{where() + ": " + s.message()};
    return std::nullopt;
}

std::optional<Fail> parseAscii(std::string_view data, const Header& h, Parse& d) {
    AsciiReader r{data.data() + h.dataOffset, data.data() + data.size(), h.lines + 1};
    std::vector<std::int64_t> list;
    for (const Element& e : h.elements) {
        for (std::uint64_t i = 0; i < e.count; ++i) {
            if (!r.nextLine())
                return Fail{"unexpected end of file: " + std::to_string(i) + " of " + std::to_string(e.count) + " " +
                            e.name + " lines present"};
            const auto where = [&] { return "line " + std::to_string(r.line) + ": " + elementWhere(e, i); };
            for (const Property& p : e.props) {
                if (!p.isList) {
                    double v = 0.0;
                    if (!r.number(p.type, v))
                        return Fail{where() + ": " + (r.atLineEnd() ? "missing" : "bad") + " value for '" + p.name + "'"};
                    storeVertexValue(d, p.role, v);
                    continue;
                }
                std::int64_t n = 0;
                if (!r.integer(n) || n < 0)
                    return Fail{where() + ": " + (r.atLineEnd() ? "missing" : "bad") + " list count for '" + p.name + "'"};
                list.clear();
                for (std::int64_t k = 0; k < n; ++k) {
                    if (r.atLineEnd())
                        return Fail{where() + ": list '" + p.name + "' has fewer than " + std::to_string(n) + " entries"};
                    if (p.role == Role::Indices) {
                        // Read as an integer: going through double would round (and overflow) large values.
                        std::int64_t index = 0;
                        if (!r.integer(index)) return Fail{where() + ": bad vertex index in '" + p.name + "'"};
                        list.push_back(index);
                        continue;
                    }
                    double v = 0.0;
                    if (!r.number(p.type, v)) return Fail{where() + ": bad value in list '" + p.name + "'"};
                }
                if (p.role == Role::Indices)
                    if (auto f = addFace(d, list.data(), list.size(), where)) return f;
            }
            if (!r.atLineEnd()) return Fail{where() + ": more values than the header declares"};
            if (auto f = endInstance(d, e, r.p)) return f;
        }
    }
    if (r.nextLine())
        return Fail{"line " + std::to_string(r.line) + ": data after the last element (header counts too small?)"};
    return std::nullopt;
}

std::optional<Fail> parseBinary(std::string_view data, const Header& h, Parse& d) {
    const bool fileBig = h.format == Format::BinaryBE;
    const bool hostBig = std::endian::native == std::endian::big;
    BinaryReader r{reinterpret_cast<const unsigned char*>(data.data()) + h.dataOffset,
                   reinterpret_cast<const unsigned char*>(data.data()) + data.size(), fileBig != hostBig};
    std::vector<std::int64_t> list;
    for (const Element& e : h.elements) {
        if (e.props.empty()) continue;  // nothing stored: a huge count must not mean a huge loop
        for (std::uint64_t i = 0; i < e.count; ++i) {
            for (const Property& p : e.props) {
                auto truncated = [&] {
                    return Fail{"file truncated in " + elementWhere(e, i) + " of " + std::to_string(e.count) +
                                " (property '" + p.name + "')"};
                };
                if (!p.isList) {
                    if (!r.has(typeSize(p.type))) return truncated();
                    const double v = r.number(p.type);
                    storeVertexValue(d, p.role, v);
                    continue;
                }
                if (!r.has(typeSize(p.countType))) return truncated();
                const std::int64_t n = r.integer(p.countType);
                if (n < 0) return Fail{elementWhere(e, i) + ": negative list count for '" + p.name + "'"};
                std::size_t bytes = 0;
                if (!detail::checkedMul(static_cast<std::size_t>(n), typeSize(p.type), bytes) || !r.has(bytes))
                    return truncated();
                if (p.role != Role::Indices) {
                    r.p += bytes;
                    continue;
                }
                list.resize(static_cast<std::size_t>(n));
                for (std::int64_t k = 0; k < n; ++k) list[static_cast<std::size_t>(k)] = r.integer(p.type);
                if (auto f = addFace(d, list.data(), list.size(), [&] { return elementWhere(e, i); })) return f;
            }
            if (auto f = endInstance(d, e, reinterpret_cast<const char*>(r.p))) return f;
        }
    }
    if (r.p != r.end) {
        // A trailing newline after the binary block is common and harmless.
        for (const unsigned char* q = r.p; q < r.end; ++q)
            if (*q != '\n' && *q != '\r' && *q != ' ' && *q != '\0')
                return Fail{std::to_string(r.end - r.p) + " bytes of data after the last element (header counts too small?)"};
    }
    return std::nullopt;
}

/// The most instances of `e` that `dataBytes` bytes of element data can hold. Binary:
/// each instance takes at least its fixed-size properties plus its list counts. ASCII:
/// each value takes at least one character and one separator (space or newline), except
/// that the file's last newline may be missing. An element without properties reads
/// nothing, so any count fits.
std::uint64_t maxInstances(Format format, const Element& e, std::uint64_t dataBytes) {
    std::uint64_t minBytes = 0;
    if (format == Format::Ascii) {
        if (!detail::checkedMul<std::uint64_t>(e.props.size(), 2, minBytes)) return 0;
    } else {
        for (const Property& p : e.props)
            if (!detail::checkedAdd<std::uint64_t>(minBytes, p.isList ? typeSize(p.countType) : typeSize(p.type), minBytes))
                return 0;
    }
    if (minBytes == 0) return UINT64_MAX;
    // dataBytes is a file size, far below 2^64 - 1, so the +1 cannot wrap.
    return (format == Format::Ascii ? dataBytes + 1 : dataBytes) / minBytes;
}

Status streamPlyImpl(const std::filesystem::path& path, MeshStreamSink& sink) {
    MappedFile file;
    if (Status s = file.open(path); !s) return s;
    const std::string_view data = file.view();
    Header h;
    if (auto f = parseHeader(data, h)) return detail::fileError(path, f->what);

    Element* vertex = nullptr;
    Element* face = nullptr;
    for (Element& e : h.elements) {
        if (e.name == "vertex" && !vertex) vertex = &e;
        if (e.name == "face" && !face) face = &e;
    }
    if (!vertex) return detail::fileError(path, "no 'vertex' element in the header");
    if (!face) return detail::fileError(path, "no 'face' element in the header (point clouds are not supported)");
    if (vertex->count > 0xFFFFFFFFull) return detail::fileError(path, "too many vertices for 32-bit indices");

    bool hasX = false, hasY = false, hasZ = false;
    int normalProps = 0;
    for (Property& p : vertex->props) {
        if (p.isList) continue;
        if (p.name == "x") { p.role = Role::X; hasX = true; }
        else if (p.name == "y") { p.role = Role::Y; hasY = true; }
        else if (p.name == "z") { p.role = Role::Z; hasZ = true; }
        else if (p.name == "nx") { p.role = Role::NX; ++normalProps; }
        else if (p.name == "ny") { p.role = Role::NY; ++normalProps; }
        else if (p.name == "nz") { p.role = Role::NZ; ++normalProps; }
    }
    if (!hasX || !hasY || !hasZ) return detail::fileError(path, "vertex element lacks an x, y or z property");
    bool hasIndices = false;
    for (Property& p : face->props) {
        if (p.isList && !hasIndices && (p.name == "vertex_indices" || p.name == "vertex_index")) {
            if (isFloat(p.type)) return detail::fileError(path, "face vertex indices have a floating-point type");
            p.role = Role::Indices;
            hasIndices = true;
        }
    }
    if (!hasIndices) return detail::fileError(path, "face element has no vertex_indices list");

    // A header count larger than the data can hold is a wrong header: say so up front.
    // (Memory does not depend on it either way: nothing is sized from header counts.)
    const std::uint64_t dataBytes = data.size() - h.dataOffset;
    for (const Element& e : h.elements)
        if (e.count > maxInstances(h.format, e, dataBytes))
            return detail::fileError(path, "header declares " + std::to_string(e.count) + " " + e.name +
                                               " entries but the file is too short (truncated?)");

    const bool withNormals = normalProps == 3;
    if (!withNormals)
        for (Property& p : vertex->props)
            if (p.role == Role::NX || p.role == Role::NY || p.role == Role::NZ) p.role = Role::Skip;
    // Only the vertex element stores values; the same roles on other elements are skipped.
    for (Element& e : h.elements)
        if (&e != vertex)
            for (Property& p : e.props)
                if (p.role != Role::Indices || &e != face) p.role = Role::Skip;

    MeshStreamLayout layout;
    layout.vertices = vertex->count;
    layout.faces = face->count;
    layout.normals = withNormals;
    layout.facesFirst = face < vertex;  // elements are in file order
    layout.bytes = data.size();
    if (Status s = sink.begin(layout); !s) return detail::fileError(path, s.message());

    Parse d(sink, file, *vertex);
    const auto fail = h.format == Format::Ascii ? parseAscii(data, h, d) : parseBinary(data, h, d);
    if (fail) return detail::fileError(path, fail->what);
    sink.progress(data.size());
    return {};
}

}  // namespace

Status streamPly(const std::filesystem::path& path, MeshStreamSink& sink) {
    try {
        return streamPlyImpl(path, sink);
    } catch (const std::exception& e) {  // e.g. std::bad_alloc in a sink on a huge but plausible file
        return detail::fileError(path, std::string("cannot load: ") + e.what());
    }
}

}  // namespace dyncull
