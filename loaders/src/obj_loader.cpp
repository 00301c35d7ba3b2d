// Wavefront OBJ reader. Our own line parser rather than tinyobjloader, which reads
// unparsable or non-finite numbers as 0 and clamps overflowing indices: every number here
// goes through std::from_chars and every index is checked where it is read, so each error
// names its line. The whole file is parsed in memory, which keeps large files fast.
#include <charconv>
#include <cmath>
#include <cstdint>
#include <exception>
#include <optional>
#include <string>
#include <string_view>
#include <unordered_map>
#include <vector>

#include "dyncull/loaders/loaders.hpp"
#include "loader_common.hpp"
#include "dyncull/objects/polygon_triangulation.hpp"

namespace dyncull {
namespace {

bool isBlank(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\f' || c == '\v'; }

// Splits one line into blank-separated words without allocating per word.
class Words {
public:
    explicit Words(std::string_view line) : rest_(line) {}
    std::optional<std::string_view> next() {
        std::size_t i = 0;
        while (i < rest_.size() && isBlank(rest_[i])) ++i;
        if (i == rest_.size()) return std::nullopt;
        std::size_t j = i;
        while (j < rest_.size() && !isBlank(rest_[j])) ++j;
        const std::string_view w = rest_.substr(i, j - i);
        rest_.remove_prefix(j);
        return w;
    }
    std::string_view rest() const {
        std::string_view r = rest_;
        while (!r.empty() && isBlank(r.front())) r.remove_prefix(1);
        while (!r.empty() && isBlank(r.back())) r.remove_suffix(1);
        return r;
    }

private:
    std::string_view rest_;
};

// Error text shows at most this much of an offending word (a hostile line can be huge).
std::string quote(std::string_view w) {
    constexpr std::size_t kMax = 40;
    return "'" + std::string(w.substr(0, kMax)) + (w.size() > kMax ? "...'" : "'");
}

// Parses a finite float; "nan", "inf", "1e99" (overflows float), "1x" all fail.
bool parseFloat(std::string_view w, float& out) {
    const char* b = w.data();
    const char* e = b + w.size();
    if (b != e && *b == '+') ++b;  // from_chars rejects a leading '+'
    const auto r = std::from_chars(b, e, out);
    return r.ec == std::errc{} && r.ptr == e && std::isfinite(out);
}

struct Fail {
    std::string what;
};

// One OBJ shape being built: its mesh and the (position, normal) pairs already used.
struct Shape {
    Mesh mesh;
    std::unordered_map<std::uint64_t, std::uint32_t> remap;
    bool allNormals = true;
};

class ObjParser {
public:
    std::optional<Fail> parse(std::string_view data, Scene& scene) {
        std::size_t pos = data.starts_with("\xEF\xBB\xBF") ? 3 : 0;  // UTF-8 byte order mark
        while (pos < data.size()) {
            std::size_t end = data.find('\n', pos);
            if (end == std::string_view::npos) end = data.size();
            ++line_;
            if (auto f = parseLine(data.substr(pos, end - pos), scene)) return f;
            pos = end + 1;
        }
        return finishShape(scene);
    }

private:
    Fail fail(const std::string& what) const { return Fail{"line " + std::to_string(line_) + ": " + what}; }

    std::optional<Fail> parseLine(std::string_view text, Scene& scene) {
        if (const std::size_t hash = text.find('#'); hash != std::string_view::npos) text = text.substr(0, hash);
        Words words(text);
        const auto key = words.next();
        if (!key) return std::nullopt;
        glm::vec3 v(0.0f);
        if (*key == "v") {
            if (auto f = readVector(words, v, 3, 7, "vertex")) return f;
            positions_.push_back(v);
            return std::nullopt;
        }
        if (*key == "vn") {
            if (auto f = readVector(words, v, 3, 3, "normal")) return f;
            normals_.push_back(v);
            return std::nullopt;
        }
        if (*key == "vt") {
            if (auto f = readVector(words, v, 1, 3, "texture coordinate")) return f;
            ++texcoords_;
            return std::nullopt;
        }
        if (*key == "f") return readFace(words);
        if (*key == "o" || *key == "g") {
            // A new group starts a new mesh once the current one has faces (as tinyobjloader did).
            if (!shape_.remap.empty())
                if (auto f = finishShape(scene)) return f;
            shape_.mesh.name = std::string(words.rest());
            return std::nullopt;
        }
        // Lines, points, materials, smoothing groups and free-form geometry are not drawn.
        static constexpr std::string_view kIgnored[] = {
            "l", "p", "s", "mg", "usemtl", "mtllib", "usemap", "maplib", "vp", "cstype", "deg", "bmat", "step",
            "curv", "curv2", "surf", "parm", "trim", "hole", "scrv", "sp", "end", "con", "bevel", "c_interp",
            "d_interp", "lod", "shadow_obj", "trace_obj", "ctech", "stech", "call", "csh"};
        for (std::string_view k : kIgnored)
            if (*key == k) return std::nullopt;
        return fail("unknown keyword " + quote(*key));
    }

    // Reads between minCount and maxCount finite numbers; only the first three are kept
    // (a 4th is the rational weight w, 4-6 are vertex colours).
    std::optional<Fail> readVector(Words& words, glm::vec3& v, int minCount, int maxCount, const char* what) {
        int count = 0;
        while (const auto w = words.next()) {
            if (count == maxCount)
                return fail(std::string(what) + " has more than " + std::to_string(maxCount) + " numbers (trailing " +
                            quote(*w) + ")");
            float f = 0.0f;
            if (!parseFloat(*w, f)) return fail(std::string(what) + ": " + quote(*w) + " is not a finite number");
            if (count < 3) v[count] = f;
            ++count;
        }
        if (count < minCount || (maxCount == 7 && count != 3 && count != 4 && count != 6 && count != 7))
            return fail(std::string(what) + " has " + std::to_string(count) + " numbers, expected " +
                        (maxCount == 7 ? std::string("3 (or 4, 6, 7)") : std::to_string(minCount) +
                                                                               (maxCount > minCount ? " to " + std::to_string(maxCount) : "")));
        return std::nullopt;
    }

    // OBJ indices are 1-based; negative ones count back from the last element read so far.
    std::optional<Fail> resolve(std::string_view w, std::size_t defined, const char* what, const char* plural,
                                std::uint32_t& out) const {
        std::int64_t i = 0;
        const auto r = std::from_chars(w.data(), w.data() + w.size(), i);
        if (r.ec != std::errc{} || r.ptr != w.data() + w.size())
            return fail(std::string(what) + " index " + quote(w) + " is not an integer");
        if (i == 0) return fail(std::string(what) + " index 0 (OBJ indices start at 1)");
        const auto n = static_cast<std::int64_t>(defined);  // readFace checked defined < 2^32
        const std::int64_t k = i > 0 ? i - 1 : n + i;
        if (k < 0 || k >= n)
            return fail(std::string(what) + " index " + std::to_string(i) + " out of range (" + std::to_string(defined) +
                        " " + plural + ")");
        out = static_cast<std::uint32_t>(k);
        return std::nullopt;
    }

    std::optional<Fail> readFace(Words& words) {
        // 32-bit mesh indices: more distinct vertices or normals than that cannot be indexed.
        if (positions_.size() > 0xFFFFFFFFull || normals_.size() > 0xFFFFFFFFull) return fail("too many vertices");
        face_.clear();
        corners_.clear();
        while (const auto w = words.next()) {
            // v, v/t, v//n or v/t/n
            const std::size_t s1 = w->find('/');
            const std::size_t s2 = s1 == std::string_view::npos ? s1 : w->find('/', s1 + 1);
            if (s2 != std::string_view::npos && w->find('/', s2 + 1) != std::string_view::npos)
                return fail("face corner " + quote(*w) + " has more than three parts");
            std::uint32_t v = 0, t = 0, nIdx = 0xFFFFFFFFu;
            if (auto f = resolve(w->substr(0, s1), positions_.size(), "vertex", "vertices", v)) return f;
            if (s1 != std::string_view::npos) {
                const std::string_view tw = w->substr(s1 + 1, s2 == std::string_view::npos ? std::string_view::npos : s2 - s1 - 1);
                if (!tw.empty())
                    if (auto f = resolve(tw, texcoords_, "texture coordinate", "texture coordinates", t)) return f;
                if (s2 != std::string_view::npos) {
                    if (auto f = resolve(w->substr(s2 + 1), normals_.size(), "normal", "normals", nIdx)) return f;
                } else if (tw.empty()) {
                    return fail("face corner " + quote(*w) + " is malformed");
                }
            }
            if (nIdx == 0xFFFFFFFFu) shape_.allNormals = false;
            const std::uint64_t key = (std::uint64_t{v} << 32) | nIdx;
            Mesh& mesh = shape_.mesh;
            if (mesh.positions.size() == 0xFFFFFFFFull) return fail("too many vertices in one shape");
            const auto [it, inserted] = shape_.remap.try_emplace(key, static_cast<std::uint32_t>(mesh.positions.size()));
            if (inserted) {
                mesh.positions.push_back(positions_[v]);
                mesh.normals.push_back(nIdx == 0xFFFFFFFFu ? glm::vec3(0.0f) : normals_[nIdx]);
            }
            face_.push_back(it->second);
            corners_.push_back(positions_[v]);
        }
        if (face_.size() < 3)
            return fail("face has " + std::to_string(face_.size()) + " corner" + (face_.size() == 1 ? "" : "s") +
                        " (a face needs at least 3)");
        local_.clear();
        switch (triangulatePolygon(corners_, local_, scratch_)) {
            case Triangulation::TooComplex:
                return fail("face with " + std::to_string(face_.size()) + " corners is too complex to triangulate");
            case Triangulation::Ok:
            case Triangulation::ZeroArea:  // covers no surface: no triangles
            case Triangulation::Tangled:   // self-intersecting: best-effort triangles
                break;
        }
        for (std::uint32_t k : local_) shape_.mesh.indices.push_back(face_[k]);
        return std::nullopt;
    }

    std::optional<Fail> finishShape(Scene& scene) {
        Shape done = std::move(shape_);
        shape_ = Shape{};
        Mesh& mesh = done.mesh;
        if (mesh.indices.empty()) return std::nullopt;  // groups with lines, points or flat faces only
        if (!done.allNormals) mesh.normals.clear();
        if (std::string problem = detail::finishMesh(mesh); !problem.empty())
            return Fail{"shape '" + mesh.name + "': " + problem};
        const auto index = static_cast<std::uint32_t>(scene.meshes.size());
        scene.instances.push_back(Instance{index, glm::mat4(1.0f), mesh.name});
        scene.meshes.push_back(std::move(mesh));
        return std::nullopt;
    }

    std::size_t line_ = 0;
    std::vector<glm::vec3> positions_, normals_;
    std::size_t texcoords_ = 0;
    Shape shape_;
    std::vector<std::uint32_t> face_, local_;
    std::vector<glm::vec3> corners_;
    TriangulationScratch scratch_;
};

Expected<Scene> loadObjImpl(const std::filesystem::path& path) {
    std::string data;
    if (Status s = detail::readWholeFile(path, data); !s) return s.error();
    Scene scene;
    ObjParser parser;
    if (auto f = parser.parse(data, scene)) return detail::fileError(path, f->what);
    if (scene.meshes.empty()) return detail::fileError(path, "no faces (nothing to draw)");
    return scene;
}

}  // namespace

Expected<Scene> loadObj(const std::filesystem::path& path) {
    try {
        return loadObjImpl(path);
    } catch (const std::exception& e) {  // e.g. std::bad_alloc
        return detail::fileError(path, std::string("cannot load: ") + e.what());
    }
}

}  // namespace dyncull
