// Scene cache reader and writer; format in scene_cache.hpp.
#include "scene_cache.hpp"

#include <bit>
#include <cmath>
#include <cstring>
#include <fstream>
#include <string>
#include <type_traits>
#include <string_view>
#include <vector>

#include "dyncull/objects/binary_file.hpp"
#include "dyncull/objects/checked_write.hpp"

namespace dyncull {
namespace {

constexpr char kMagic[8] = {'D', 'Y', 'N', 'C', 'S', 'C', 'N', '\0'};

bool finite(const glm::vec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

/// Structural checks a traversal relies on: depth-first layout, child links inside the
/// subtree, index ranges inside the mesh, sane axes and finite boxes.
std::string validateTree(const LocalBsp& bsp) {
    const std::size_t n = bsp.nodes.size();
    if (n == 0) return "no nodes";
    if (n > 0xFFFFFFF0u) return "too many nodes";
    for (std::size_t i = 0; i < n; ++i) {
        const LocalBspNode& node = bsp.nodes[i];
        const std::string at = "node " + std::to_string(i) + ": ";
        if (node.subtreeSize == 0 || node.subtreeSize > n - i) return at + "subtree size out of range";
        if (node.indexCount % 3 != 0 || node.firstIndex > bsp.mesh.indices.size() ||
            node.indexCount > bsp.mesh.indices.size() - node.firstIndex)
            return at + "index range out of range";
        if (node.axis > 2) return at + "axis out of range";
        if (!node.box.empty() && !node.box.finite()) return at + "non-finite box";
        if (!std::isfinite(node.split)) return at + "non-finite split";
        const bool leaf0 = node.children[0] == kInvalidIndex, leaf1 = node.children[1] == kInvalidIndex;
        if (leaf0 != leaf1) return at + "half a leaf";
        if (leaf0) {
            if (node.subtreeSize != 1) return at + "leaf with a subtree";
            continue;
        }
        const std::size_t c0 = node.children[0], c1 = node.children[1];
        if (c0 != i + 1 || c1 <= c0 || c1 >= i + node.subtreeSize) return at + "child out of its subtree";
        if (bsp.nodes[c0].subtreeSize != c1 - c0 || c1 + bsp.nodes[c1].subtreeSize != i + node.subtreeSize)
            return at + "children do not tile the subtree";
    }
    if (bsp.nodes[0].subtreeSize != n) return "root does not span the tree";
    return {};
}

Error bad(const std::filesystem::path& path, const std::string& why) {
    return Error{"scene cache " + path.string() + ": " + why};
}

}  // namespace

Status writeSceneCache(const std::filesystem::path& path, const PreparedScene& scene, std::uint64_t paramsHash) {
    std::filesystem::path tmp = path;
    tmp += ".tmp";
    std::ofstream f;
    if (Status s = openChecked(f, tmp); !s) return Error{"scene cache " + s.message()};
    const char zeros[kSceneCacheHeaderSize] = {};
    f.write(zeros, sizeof zeros);  // the header, filled in once the payload's size and hash are known
    BinaryWriter w(f);
    w.put(static_cast<std::uint32_t>(scene.models.size()));
    for (const LocalBsp& b : scene.models) {
        w.str<std::uint32_t>(b.mesh.name);
        w.array<std::uint32_t>(b.mesh.positions);
        w.array<std::uint32_t>(b.mesh.normals);
        w.array<std::uint32_t>(b.mesh.indices);
        w.put(static_cast<std::uint32_t>(b.nodes.size()));
        for (const LocalBspNode& n : b.nodes) {
            w.put(n.box.min);
            w.put(n.box.max);
            w.put(n.children[0]);
            w.put(n.children[1]);
            w.put(n.firstIndex);
            w.put(n.indexCount);
            w.put(n.subtreeSize);
            w.put(n.split);
            w.put(n.axis);
            w.put(n.depth);
        }
        w.put(static_cast<std::uint64_t>(b.stats.trianglesBefore));
        w.put(static_cast<std::uint64_t>(b.stats.trianglesAfter));
        w.put(b.stats.leaves);
        w.put(b.stats.depth);
        w.put(b.stats.stalledLeaves);
        w.put(b.stats.buildMs);
        w.put(static_cast<std::uint8_t>(b.faces));
    }
    w.put(static_cast<std::uint32_t>(scene.objects.size()));
    for (const PlacedObject& o : scene.objects) {
        w.put(o.model);
        w.put(o.transform.translation);
        w.put(glm::vec4(o.transform.rotation.w, o.transform.rotation.x, o.transform.rotation.y, o.transform.rotation.z));
        w.put(o.transform.scale);
        w.put(static_cast<std::uint8_t>(o.isStatic ? 1 : 0));
    }
    const std::uint64_t payload = w.size(), sum = w.hash();
    const std::uint32_t version = kSceneCacheVersion, headerSize = kSceneCacheHeaderSize;
    char h[kSceneCacheHeaderSize] = {};
    std::memcpy(h, kMagic, 8);
    std::memcpy(h + 8, &version, 4);
    std::memcpy(h + 12, &headerSize, 4);
    std::memcpy(h + 16, &paramsHash, 8);
    std::memcpy(h + 24, &payload, 8);
    std::memcpy(h + 32, &sum, 8);
    f.seekp(0);
    f.write(h, sizeof h);
    // The close flushes the last buffer: a full disk may show only here.
    if (Status s = closeChecked(f, tmp); !s) return Error{"scene cache " + s.message()};
    std::error_code ec;
    std::filesystem::rename(tmp, path, ec);
    if (ec) return Error{"scene cache " + path.string() + ": cannot rename into place: " + ec.message()};
    return {};
}

Expected<PreparedScene> readSceneCache(const std::filesystem::path& path, std::uint64_t paramsHash) {
    std::ifstream f(path, std::ios::binary | std::ios::ate);
    if (!f) return bad(path, "cannot open");
    const std::streamoff end = f.tellg();
    if (end < 0) return bad(path, "cannot size");
    const std::size_t size = static_cast<std::size_t>(end);
    if (size < kSceneCacheHeaderSize) return bad(path, "truncated header (" + std::to_string(size) + " bytes)");
    char header[kSceneCacheHeaderSize];
    f.seekg(0);
    f.read(header, kSceneCacheHeaderSize);
    if (!f) return bad(path, "cannot read header");
    if (std::memcmp(header, kMagic, 8) != 0) return bad(path, "bad magic (not a dyncull scene cache)");
    std::uint32_t version = 0, headerSize = 0;
    std::uint64_t hash = 0, payload = 0, sum = 0;
    std::memcpy(&version, header + 8, 4);
    std::memcpy(&headerSize, header + 12, 4);
    std::memcpy(&hash, header + 16, 8);
    std::memcpy(&payload, header + 24, 8);
    std::memcpy(&sum, header + 32, 8);
    if (version != kSceneCacheVersion)
        return bad(path, "format version " + std::to_string(version) + ", expected " + std::to_string(kSceneCacheVersion));
    if (headerSize != kSceneCacheHeaderSize) return bad(path, "header size " + std::to_string(headerSize));
    if (hash != paramsHash) return bad(path, "stale (written for other generator parameters)");
    if (payload != size - kSceneCacheHeaderSize)
        return bad(path, "truncated or padded: header says " + std::to_string(payload) + " payload bytes, file has " +
                             std::to_string(size - kSceneCacheHeaderSize));
    if (std::string why = checkPayload(f, payload, sum); !why.empty()) return bad(path, why);
    f.seekg(static_cast<std::streamoff>(kSceneCacheHeaderSize));
    BinaryReader r(f, payload);
    PreparedScene scene;
    const std::uint32_t models = r.get<std::uint32_t>();
    // Every model takes well over 16 bytes, so a larger count is corrupt, not a big scene.
    if (r.failed() || models > r.left() / 16) return bad(path, "model count out of range");
    scene.models.resize(models);
    for (std::uint32_t i = 0; i < models; ++i) {
        LocalBsp& b = scene.models[i];
        const std::string at = "model " + std::to_string(i) + ": ";
        if (!r.str<std::uint32_t>(b.mesh.name, 4096) || !r.array<std::uint32_t>(b.mesh.positions) ||
            !r.array<std::uint32_t>(b.mesh.normals) || !r.array<std::uint32_t>(b.mesh.indices))
            return bad(path, at + "truncated mesh");
        if (std::string why = validateMesh(b.mesh); !why.empty()) return bad(path, at + why);
        if (std::string why = validateNormals(b.mesh); !why.empty()) return bad(path, at + why);
        const std::uint32_t nodes = r.get<std::uint32_t>();
        constexpr std::size_t kNodeBytes = 24 + 4 * 5 + 4 + 2;
        if (r.failed() || nodes > r.left() / kNodeBytes) return bad(path, at + "node count out of range");
        b.nodes.resize(nodes);
        for (LocalBspNode& n : b.nodes) {
            n.box.min = r.get<glm::vec3>();
            n.box.max = r.get<glm::vec3>();
            n.children[0] = r.get<std::uint32_t>();
            n.children[1] = r.get<std::uint32_t>();
            n.firstIndex = r.get<std::uint32_t>();
            n.indexCount = r.get<std::uint32_t>();
            n.subtreeSize = r.get<std::uint32_t>();
            n.split = r.get<float>();
            n.axis = r.get<std::uint8_t>();
            n.depth = r.get<std::uint8_t>();
        }
        b.stats.trianglesBefore = static_cast<std::size_t>(r.get<std::uint64_t>());
        b.stats.trianglesAfter = static_cast<std::size_t>(r.get<std::uint64_t>());
        b.stats.leaves = r.get<std::uint32_t>();
        b.stats.depth = r.get<std::uint32_t>();
        b.stats.stalledLeaves = r.get<std::uint32_t>();
        b.stats.buildMs = r.get<double>();
        const auto faces = r.get<std::uint8_t>();
        if (r.failed()) return bad(path, at + "truncated tree");
        if (faces > static_cast<std::uint8_t>(FaceMode::TwoSided)) return bad(path, at + "unknown face mode " + std::to_string(faces));
        b.faces = static_cast<FaceMode>(faces);
        if (!std::isfinite(b.stats.buildMs) || b.stats.buildMs < 0.0) return bad(path, at + "build time is not a finite duration");
        if (std::string why = validateTree(b); !why.empty()) return bad(path, at + why);
    }
    const std::uint32_t objects = r.get<std::uint32_t>();
    constexpr std::size_t kObjectBytes = 4 + 12 + 16 + 12 + 1;
    if (r.failed() || objects > r.left() / kObjectBytes) return bad(path, "object count out of range");
    scene.objects.resize(objects);
    for (std::uint32_t i = 0; i < objects; ++i) {
        PlacedObject& o = scene.objects[i];
        o.model = r.get<std::uint32_t>();
        o.transform.translation = r.get<glm::vec3>();
        const glm::vec4 q = r.get<glm::vec4>();
        o.transform.rotation = glm::quat(q.x, q.y, q.z, q.w);
        o.transform.scale = r.get<glm::vec3>();
        const std::uint8_t isStatic = r.get<std::uint8_t>();
        if (r.failed()) return bad(path, "truncated objects");
        if (o.model >= models) return bad(path, "object " + std::to_string(i) + ": model out of range");
        if (isStatic > 1) return bad(path, "object " + std::to_string(i) + ": bad static flag");
        o.isStatic = isStatic == 1;
        if (!finite(o.transform.translation) || !finite(o.transform.scale))
            return bad(path, "object " + std::to_string(i) + ": non-finite transform");
        if (Status s = validateTransform(o.transform); !s) return bad(path, "object " + std::to_string(i) + ": " + s.message());
    }
    if (r.left() != 0) return bad(path, std::to_string(r.left()) + " trailing payload bytes");
    return scene;
}

}  // namespace dyncull
