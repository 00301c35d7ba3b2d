// glTF 2.0 loading (.gltf and .glb) through tinygltf. tinygltf parses JSON and buffers;
// we read accessors ourselves (byteStride, every component type, bounds checks), merge a
// mesh's triangle primitives into one dyncull Mesh and walk the node hierarchy.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <exception>
#include <limits>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <glm/gtc/quaternion.hpp>
#include <nlohmann/json.hpp>
#include <tiny_gltf.h>

#include "dyncull/loaders/loaders.hpp"
#include "dyncull/objects/file_extension.hpp"
#include "dyncull/objects/transform.hpp"
#include "loader_common.hpp"

namespace dyncull {
namespace {

struct Fail {
    std::string what;
};

// Images are irrelevant for culling; skipping them also means a missing texture file
// does not fail the load.
bool ignoreImage(tinygltf::Image*, const int, std::string*, std::string*, int, int, const unsigned char*, int, void*) {
    return true;
}

constexpr const char* kDraco = "KHR_draco_mesh_compression";

std::string dracoMessage() {
    return std::string("the geometry is Draco-compressed (") + kDraco +
           "), which dyncull does not decode; decompress the file first, e.g. with glTF Transform: "
           "npx @gltf-transform/cli copy in.glb out.glb (its copy command removes Draco compression)";
}

// glTF needs fewer than 10 levels; the limit only has to stop a recursive JSON parser
// from running out of stack.
constexpr int kMaxJsonDepth = 64;

// True when `text` nests arrays/objects deeper than `limit`. Brackets inside strings do
// not count; a malformed text is left for the JSON parser to report.
bool jsonNestsDeeperThan(std::string_view text, int limit) {
    int depth = 0;
    bool inString = false;
    for (std::size_t i = 0; i < text.size(); ++i) {
        const char c = text[i];
        if (inString) {
            if (c == '\\') ++i;  // the escaped character cannot end the string
            else if (c == '"') inString = false;
        } else if (c == '"') {
            inString = true;
        } else if (c == '[' || c == '{') {
            if (++depth > limit) return true;
        } else if ((c == ']' || c == '}') && depth > 0) {
            --depth;
        }
    }
    return false;
}

// Checks the GLB header and chunk table (tinygltf does not check the version, and lets
// the BIN chunk end up to 8 bytes past the file) and returns the JSON chunk in `json`.
std::optional<Fail> checkGlb(const std::string& bytes, std::string_view& json) {
    auto u32 = [&](std::size_t at) {
        std::uint32_t v;
        std::memcpy(&v, bytes.data() + at, 4);  // little-endian, as is every host we build for
        return v;
    };
    if (bytes.size() < 20) return Fail{"GLB file shorter than its 20-byte header"};
    if (bytes.compare(0, 4, "glTF") != 0) return Fail{"not a GLB file (no 'glTF' magic)"};
    if (u32(4) != 2) return Fail{"GLB version " + std::to_string(u32(4)) + " is not supported (only version 2)"};
    const std::uint64_t length = u32(8);
    if (length > bytes.size())
        return Fail{"GLB header length " + std::to_string(length) + " exceeds the file size " +
                    std::to_string(bytes.size())};
    const std::uint64_t jsonLength = u32(12);
    if (u32(16) != 0x4E4F534Au) return Fail{"GLB first chunk is not JSON"};
    if (jsonLength == 0 || !detail::rangeInside(20, jsonLength, length))
        return Fail{"GLB JSON chunk length " + std::to_string(jsonLength) + " does not fit in the file"};
    const std::uint64_t binAt = 20 + jsonLength;
    if (binAt < length) {
        if (!detail::rangeInside(binAt, 8, length)) return Fail{"GLB chunk header after the JSON chunk is truncated"};
        const std::uint64_t binLength = u32(static_cast<std::size_t>(binAt));
        if (!detail::rangeInside(binAt + 8, binLength, length))
            return Fail{"GLB BIN chunk length " + std::to_string(binLength) + " runs past the end of the file"};
    }
    json = std::string_view(bytes).substr(20, static_cast<std::size_t>(jsonLength));
    return std::nullopt;
}

// tinygltf's own file callbacks open the file to test that it exists (which blocks on a
// pipe) and read directories and devices (a buffer uri of "." asks it to allocate the size
// a directory stream reports): external buffers must be regular files.
bool bufferFileExists(const std::string& filepath, void*) {
    std::error_code ec;
    return std::filesystem::exists(filepath, ec);
}

bool readBufferFile(std::vector<unsigned char>* out, std::string* err, const std::string& filepath, void*) {
    std::error_code ec;
    if (!std::filesystem::is_regular_file(filepath, ec)) {
        if (err) *err += "not a regular file (a directory, device or pipe)";  // tinygltf has named the path
        return false;
    }
    std::string bytes;
    if (Status s = detail::readWholeFile(filepath, bytes); !s) {
        if (err) *err += s.message();
        return false;
    }
    out->assign(bytes.begin(), bytes.end());
    return true;
}

// Required extensions that only change materials, textures or lights (which culling
// ignores) or allow component types the accessor reader handles anyway.
bool canIgnoreRequired(const std::string& ext) {
    static const char* const kIgnorable[] = {"KHR_mesh_quantization", "KHR_texture_transform", "KHR_texture_basisu",
                                             "EXT_texture_webp", "EXT_texture_avif", "KHR_lights_punctual"};
    for (const char* e : kIgnorable)
        if (ext == e) return true;
    return ext.rfind("KHR_materials_", 0) == 0;
}

// A validated view of an accessor's bytes.
struct AccessorView {
    const unsigned char* base = nullptr;
    std::size_t stride = 0;
    std::size_t count = 0;
    int componentType = 0;
    int components = 0;
    bool normalized = false;
};

std::optional<Fail> viewAccessor(const tinygltf::Model& model, int index, int wantComponents, AccessorView& out) {
    const std::string where = "accessor " + std::to_string(index);
    if (index < 0 || static_cast<std::size_t>(index) >= model.accessors.size()) return Fail{where + " does not exist"};
    const tinygltf::Accessor& a = model.accessors[static_cast<std::size_t>(index)];
    if (a.sparse.isSparse) return Fail{where + ": sparse accessors are not supported"};
    if (a.bufferView < 0 || static_cast<std::size_t>(a.bufferView) >= model.bufferViews.size())
        return Fail{where + ": no valid bufferView"};
    const std::string viewName = "bufferView " + std::to_string(a.bufferView);
    const tinygltf::BufferView& bv = model.bufferViews[static_cast<std::size_t>(a.bufferView)];
    if (bv.buffer < 0 || static_cast<std::size_t>(bv.buffer) >= model.buffers.size())
        return Fail{viewName + " (of " + where + ") refers to a missing buffer"};
    const tinygltf::Buffer& buf = model.buffers[static_cast<std::size_t>(bv.buffer)];
    const std::uint64_t bufSize = buf.data.size();
    if (bv.byteOffset > bufSize)
        return Fail{viewName + ": byteOffset " + std::to_string(bv.byteOffset) + " is past the end of buffer " +
                    std::to_string(bv.buffer) + " (" + std::to_string(bufSize) + " bytes)"};
    if (!detail::rangeInside(bv.byteOffset, bv.byteLength, bufSize))
        return Fail{viewName + ": byteLength " + std::to_string(bv.byteLength) + " at byteOffset " +
                    std::to_string(bv.byteOffset) + " reads past the end of buffer " + std::to_string(bv.buffer) +
                    " (" + std::to_string(bufSize) + " bytes)"};

    const int compSize = tinygltf::GetComponentSizeInBytes(static_cast<std::uint32_t>(a.componentType));
    const int comps = tinygltf::GetNumComponentsInType(static_cast<std::uint32_t>(a.type));
    if (compSize <= 0 || comps <= 0) return Fail{where + ": unknown component type or element type"};
    if (comps != wantComponents)
        return Fail{where + ": has " + std::to_string(comps) + " components, expected " + std::to_string(wantComponents)};
    const std::uint64_t elemSize = static_cast<std::uint64_t>(compSize) * static_cast<std::uint64_t>(comps);  // <= 8 * 16
    std::uint64_t stride = elemSize;
    if (bv.byteStride != 0) {
        // glTF 2.0 allows 4..252 in steps of 4 (tinygltf enforces only the upper bound and the step).
        if (bv.byteStride < 4 || bv.byteStride > 252 || bv.byteStride % 4 != 0)
            return Fail{viewName + ": byteStride " + std::to_string(bv.byteStride) +
                        " is not a multiple of 4 in 4..252"};
        if (bv.byteStride < elemSize)
            return Fail{viewName + ": byteStride " + std::to_string(bv.byteStride) + " is smaller than the " +
                        std::to_string(elemSize) + "-byte elements of " + where};
        stride = bv.byteStride;
    }
    if (a.byteOffset > bv.byteLength)
        return Fail{where + ": byteOffset " + std::to_string(a.byteOffset) + " is past the end of " + viewName +
                    " (" + std::to_string(bv.byteLength) + " bytes)"};
    // The last element must lie inside the buffer view: byteOffset + stride * (count - 1) + elemSize.
    std::uint64_t span = 0;
    if (a.count > 0 && (!detail::checkedMul<std::uint64_t>(stride, a.count - 1, span) ||
                        !detail::checkedAdd<std::uint64_t>(span, elemSize, span) ||
                        !detail::rangeInside(a.byteOffset, span, bv.byteLength)))
        return Fail{where + ": count " + std::to_string(a.count) + " (stride " + std::to_string(stride) +
                    ", byteOffset " + std::to_string(a.byteOffset) + ") reads past the end of " + viewName + " (" +
                    std::to_string(bv.byteLength) + " bytes)"};
    // Both offsets are now known to lie inside the buffer, so their sum does too.
    out.base = buf.data.data() + bv.byteOffset + a.byteOffset;
    out.stride = static_cast<std::size_t>(stride);
    out.count = a.count;
    out.componentType = a.componentType;
    out.components = comps;
    out.normalized = a.normalized;
    return std::nullopt;
}

template <class T>
T loadRaw(const unsigned char* p) {
    T v;
    std::memcpy(&v, p, sizeof(T));  // glTF data is little-endian, as is every host we build for
    return v;
}

// Component `c` of element `i` as float, applying glTF's normalised-integer rules.
float readFloat(const AccessorView& v, std::size_t i, int c) {
    const unsigned char* p = v.base + i * v.stride;
    switch (v.componentType) {
        case TINYGLTF_COMPONENT_TYPE_FLOAT: return loadRaw<float>(p + 4 * c);
        case TINYGLTF_COMPONENT_TYPE_BYTE: {
            const float x = loadRaw<std::int8_t>(p + c);
            return v.normalized ? std::max(x / 127.0f, -1.0f) : x;
        }
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: {
            const float x = loadRaw<std::uint8_t>(p + c);
            return v.normalized ? x / 255.0f : x;
        }
        case TINYGLTF_COMPONENT_TYPE_SHORT: {
            const float x = loadRaw<std::int16_t>(p + 2 * c);
            return v.normalized ? std::max(x / 32767.0f, -1.0f) : x;
        }
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: {
            const float x = loadRaw<std::uint16_t>(p + 2 * c);
            return v.normalized ? x / 65535.0f : x;
        }
        case TINYGLTF_COMPONENT_TYPE_INT: return static_cast<float>(loadRaw<std::int32_t>(p + 4 * c));
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: return static_cast<float>(loadRaw<std::uint32_t>(p + 4 * c));
        case TINYGLTF_COMPONENT_TYPE_DOUBLE: return static_cast<float>(loadRaw<double>(p + 8 * c));
    }
    return 0.0f;
}

// Index element `i` as a signed 64-bit value (negative means invalid); floats rejected by caller.
std::int64_t readIndex(const AccessorView& v, std::size_t i) {
    const unsigned char* p = v.base + i * v.stride;
    switch (v.componentType) {
        case TINYGLTF_COMPONENT_TYPE_BYTE: return loadRaw<std::int8_t>(p);
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: return loadRaw<std::uint8_t>(p);
        case TINYGLTF_COMPONENT_TYPE_SHORT: return loadRaw<std::int16_t>(p);
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: return loadRaw<std::uint16_t>(p);
        case TINYGLTF_COMPONENT_TYPE_INT: return loadRaw<std::int32_t>(p);
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: return loadRaw<std::uint32_t>(p);
    }
    return -1;
}

std::optional<Fail> readVec3(const tinygltf::Model& model, int accessor, std::vector<glm::vec3>& out) {
    AccessorView v;
    if (auto f = viewAccessor(model, accessor, 3, v)) return f;
    out.resize(v.count);
    for (std::size_t i = 0; i < v.count; ++i) out[i] = {readFloat(v, i, 0), readFloat(v, i, 1), readFloat(v, i, 2)};
    return std::nullopt;
}

// Appends one primitive to `mesh` (vertices offset by the current vertex count).
// Returns false in `used` for primitives that are not surfaces (points, lines).
std::optional<Fail> appendPrimitive(const tinygltf::Model& model, const tinygltf::Primitive& prim, Mesh& mesh,
                                    bool& allNormals, bool& used) {
    used = false;
    const int mode = prim.mode < 0 ? TINYGLTF_MODE_TRIANGLES : prim.mode;
    if (mode != TINYGLTF_MODE_TRIANGLES && mode != TINYGLTF_MODE_TRIANGLE_STRIP && mode != TINYGLTF_MODE_TRIANGLE_FAN)
        return std::nullopt;
    const auto posIt = prim.attributes.find("POSITION");
    if (posIt == prim.attributes.end()) return std::nullopt;  // nothing to place (allowed by the spec)
    // A Draco primitive's accessors may carry an uncompressed fallback; without one they
    // have no bufferView and only the Draco stream holds the geometry.
    if (prim.extensions.count(kDraco) && posIt->second >= 0 &&
        static_cast<std::size_t>(posIt->second) < model.accessors.size() &&
        model.accessors[static_cast<std::size_t>(posIt->second)].bufferView < 0)
        return Fail{dracoMessage()};

    std::vector<glm::vec3> pos, nrm;
    if (auto f = readVec3(model, posIt->second, pos)) return Fail{"POSITION " + f->what};
    const auto nIt = prim.attributes.find("NORMAL");
    if (nIt != prim.attributes.end()) {
        if (auto f = readVec3(model, nIt->second, nrm)) return Fail{"NORMAL " + f->what};
        if (nrm.size() != pos.size()) return Fail{"NORMAL count differs from POSITION count"};
    }
    for (std::size_t i = 0; i < pos.size(); ++i)
        if (!std::isfinite(pos[i].x) || !std::isfinite(pos[i].y) || !std::isfinite(pos[i].z))
            return Fail{"vertex " + std::to_string(i) + " has a non-finite coordinate"};

    std::vector<std::uint32_t> idx;
    if (prim.indices >= 0) {
        AccessorView v;
        if (auto f = viewAccessor(model, prim.indices, 1, v)) return Fail{"indices " + f->what};
        if (v.componentType == TINYGLTF_COMPONENT_TYPE_FLOAT || v.componentType == TINYGLTF_COMPONENT_TYPE_DOUBLE)
            return Fail{"indices accessor " + std::to_string(prim.indices) + " has a floating-point type"};
        idx.resize(v.count);
        for (std::size_t i = 0; i < v.count; ++i) {
            const std::int64_t k = readIndex(v, i);
            if (k < 0 || static_cast<std::uint64_t>(k) >= pos.size())
                return Fail{"index " + std::to_string(k) + " at position " + std::to_string(i) + " out of range (" +
                            std::to_string(pos.size()) + " vertices)"};
            idx[i] = static_cast<std::uint32_t>(k);
        }
    } else {
        idx.resize(pos.size());
        for (std::size_t i = 0; i < idx.size(); ++i) idx[i] = static_cast<std::uint32_t>(i);
    }

    std::uint64_t total = 0;
    if (!detail::checkedAdd<std::uint64_t>(mesh.positions.size(), pos.size(), total) ||
        total > std::numeric_limits<std::uint32_t>::max())
        return Fail{"more than 2^32 - 1 vertices in one mesh"};
    const auto base = static_cast<std::uint32_t>(mesh.positions.size());
    auto tri = [&](std::uint32_t a, std::uint32_t b, std::uint32_t c) {
        mesh.indices.push_back(base + a);
        mesh.indices.push_back(base + b);
        mesh.indices.push_back(base + c);
    };
    if (mode == TINYGLTF_MODE_TRIANGLES) {
        if (idx.size() % 3 != 0) return Fail{"triangle list index count " + std::to_string(idx.size()) + " is not a multiple of 3"};
        for (std::size_t i = 0; i + 2 < idx.size(); i += 3) tri(idx[i], idx[i + 1], idx[i + 2]);
    } else if (mode == TINYGLTF_MODE_TRIANGLE_STRIP) {
        // Every other strip triangle swaps its first two corners to keep the winding.
        for (std::size_t i = 0; i + 2 < idx.size(); ++i)
            if (i % 2 == 0) tri(idx[i], idx[i + 1], idx[i + 2]);
            else tri(idx[i + 1], idx[i], idx[i + 2]);
    } else {
        for (std::size_t i = 1; i + 1 < idx.size(); ++i) tri(idx[0], idx[i], idx[i + 1]);
    }
    mesh.positions.insert(mesh.positions.end(), pos.begin(), pos.end());
    if (nrm.empty()) allNormals = false;
    else if (allNormals) mesh.normals.insert(mesh.normals.end(), nrm.begin(), nrm.end());
    used = true;
    return std::nullopt;
}

std::optional<Fail> buildMesh(const tinygltf::Model& model, int meshIndex, Mesh& mesh) {
    const tinygltf::Mesh& src = model.meshes[static_cast<std::size_t>(meshIndex)];
    mesh.name = src.name.empty() ? "mesh " + std::to_string(meshIndex) : src.name;
    bool allNormals = true;
    for (std::size_t p = 0; p < src.primitives.size(); ++p) {
        bool used = false;
        if (auto f = appendPrimitive(model, src.primitives[p], mesh, allNormals, used))
            return Fail{"mesh " + std::to_string(meshIndex) + " primitive " + std::to_string(p) + ": " + f->what};
    }
    if (!allNormals) mesh.normals.clear();
    if (mesh.indices.empty()) return std::nullopt;  // no surfaces: caller skips it
    if (std::string problem = detail::finishMesh(mesh); !problem.empty())
        return Fail{"mesh " + std::to_string(meshIndex) + ": " + problem};
    return std::nullopt;
}

std::string nodeName(int index, const tinygltf::Node& n) {
    return "node " + std::to_string(index) + (n.name.empty() ? std::string() : " ('" + n.name + "')");
}

// The node's local matrix in double: hierarchies far from the origin (1e7 and beyond)
// lose whole units when composed in float.
std::optional<Fail> localMatrix(const tinygltf::Node& n, glm::dmat4& m) {
    if (!n.matrix.empty()) {
        if (n.matrix.size() != 16) return Fail{"matrix has " + std::to_string(n.matrix.size()) + " elements, expected 16"};
        for (int c = 0; c < 4; ++c)
            for (int r = 0; r < 4; ++r) m[c][r] = n.matrix[static_cast<std::size_t>(4 * c + r)];  // column-major, like glm
        // Node matrices must be affine; a projective bottom row makes w vary per vertex
        // (0 0 0 0 sends every vertex to infinity). Exporters write it exactly.
        constexpr double kTol = 1e-9;
        if (std::abs(m[0][3]) > kTol || std::abs(m[1][3]) > kTol || std::abs(m[2][3]) > kTol ||
            std::abs(m[3][3] - 1.0) > kTol)
            return Fail{"matrix is not affine (bottom row " + std::to_string(m[0][3]) + " " + std::to_string(m[1][3]) +
                        " " + std::to_string(m[2][3]) + " " + std::to_string(m[3][3]) + ", expected 0 0 0 1)"};
        return std::nullopt;
    }
    if (!n.scale.empty() && n.scale.size() != 3) return Fail{"scale has " + std::to_string(n.scale.size()) + " elements, expected 3"};
    if (!n.rotation.empty() && n.rotation.size() != 4)
        return Fail{"rotation has " + std::to_string(n.rotation.size()) + " elements, expected 4"};
    if (!n.translation.empty() && n.translation.size() != 3)
        return Fail{"translation has " + std::to_string(n.translation.size()) + " elements, expected 3"};
    m = glm::dmat4(1.0);
    if (n.scale.size() == 3) {
        m[0][0] = n.scale[0];
        m[1][1] = n.scale[1];
        m[2][2] = n.scale[2];
    }
    if (n.rotation.size() == 4) {
        // glTF stores (x, y, z, w); glm::dquat's constructor takes (w, x, y, z).
        const glm::dquat q(n.rotation[3], n.rotation[0], n.rotation[1], n.rotation[2]);
        m = glm::mat4_cast(q) * m;
    }
    if (n.translation.size() == 3) m[3] = glm::dvec4(n.translation[0], n.translation[1], n.translation[2], 1.0);
    return std::nullopt;
}

// Largest world coordinate accepted: products of two (squared distances, plane tests) stay far inside float range.
constexpr double kMaxWorldCoordinate = 1e15;

// Instance transforms are stored relative to Scene::origin when the scene lies farther
// from the file's origin than this many times its own radius: beyond that, float
// translations lose more than ~1e-6 of the scene's size.
constexpr double kRecentreRatio = 16.0;

// tinygltf reads an optional size field that is not a whole number in 0..2^64-1 (2^64 and
// above, negative, fractional) as absent, i.e. 0: a wrong model rather than an error.
// Check the raw JSON's offsets, lengths, strides and counts first (the depth check above
// keeps this parse's recursion bounded).
std::optional<Fail> checkSizeFields(std::string_view json) {
    const nlohmann::json doc = nlohmann::json::parse(json.begin(), json.end(), nullptr, false);
    if (doc.is_discarded() || !doc.is_object()) return std::nullopt;  // tinygltf reports the syntax error
    struct Fields {
        const char* array;
        std::initializer_list<const char*> names;
    };
    for (const Fields& f : {Fields{"buffers", {"byteLength"}}, Fields{"bufferViews", {"buffer", "byteOffset", "byteLength", "byteStride"}},
                            Fields{"accessors", {"bufferView", "byteOffset", "count"}}}) {
        const auto arr = doc.find(f.array);
        if (arr == doc.end() || !arr->is_array()) continue;
        for (std::size_t i = 0; i < arr->size(); ++i) {
            const nlohmann::json& item = (*arr)[i];
            if (!item.is_object()) continue;
            for (const char* name : f.names) {
                const auto v = item.find(name);
                if (v != item.end() && !v->is_number_unsigned())
                    return Fail{std::string(f.array) + "[" + std::to_string(i) + "]." + name + " is " + v->dump() +
                                ", not a whole number in 0..2^64-1"};
            }
        }
    }
    return std::nullopt;
}

struct PendingInstance {
    std::uint32_t mesh;
    glm::dmat4 world;
    int node;
};

Expected<Scene> loadGltfImpl(const std::filesystem::path& path) {
    std::string bytes;
    if (Status s = detail::readWholeFile(path, bytes); !s) return s.error();
    if (bytes.size() > std::numeric_limits<unsigned int>::max())
        return detail::fileError(path, "larger than 4 GiB, which tinygltf cannot address");
    const bool binary = lowercaseExtension(path) == ".glb";
    std::string_view json = bytes;
    if (binary)
        if (auto f = checkGlb(bytes, json)) return detail::fileError(path, f->what);
    if (jsonNestsDeeperThan(json, kMaxJsonDepth))
        return detail::fileError(path, "JSON nests deeper than " + std::to_string(kMaxJsonDepth) +
                                           " levels (glTF needs fewer than 10)");

    if (auto f = checkSizeFields(json)) return detail::fileError(path, f->what);

    tinygltf::TinyGLTF loader;
    loader.SetImageLoader(ignoreImage, nullptr);
    loader.SetFsCallbacks({&bufferFileExists, &tinygltf::ExpandFilePath, &readBufferFile, &tinygltf::WriteWholeFile, nullptr});
    tinygltf::Model model;
    std::string err, warn;
    const std::string baseDir = path.parent_path().string();
    const bool ok = binary ? loader.LoadBinaryFromMemory(&model, &err, &warn, reinterpret_cast<const unsigned char*>(bytes.data()),
                                                         static_cast<unsigned int>(bytes.size()), baseDir)
                           : loader.LoadASCIIFromString(&model, &err, &warn, bytes.data(),
                                                        static_cast<unsigned int>(bytes.size()), baseDir);
    if (!ok) {
        if (err.empty()) err = "cannot parse glTF";
        // tinygltf rejects a Draco primitive's indices accessor (no bufferView) before we
        // see the extension: name the real cause, keep the parser's words.
        if (json.find(kDraco) != std::string_view::npos) return detail::fileError(path, dracoMessage() + " (" + err + ")");
        return detail::fileError(path, err);
    }
    for (const std::string& e : model.extensionsRequired) {
        if (e == kDraco) return detail::fileError(path, dracoMessage());
        if (!canIgnoreRequired(e)) return detail::fileError(path, "requires the unsupported extension " + e);
    }
    if (model.meshes.empty()) return detail::fileError(path, "no meshes");

    // Roots: the default scene, else scene 0, else every node that is nobody's child.
    std::vector<int> roots;
    if (!model.scenes.empty()) {
        const int s = model.defaultScene >= 0 && static_cast<std::size_t>(model.defaultScene) < model.scenes.size()
                          ? model.defaultScene : 0;
        roots = model.scenes[static_cast<std::size_t>(s)].nodes;
    } else {
        std::vector<char> isChild(model.nodes.size(), 0);
        for (const tinygltf::Node& n : model.nodes)
            for (int c : n.children)
                if (c >= 0 && static_cast<std::size_t>(c) < model.nodes.size()) isChild[static_cast<std::size_t>(c)] = 1;
        for (std::size_t i = 0; i < model.nodes.size(); ++i)
            if (!isChild[i]) roots.push_back(static_cast<int>(i));
    }

    Scene scene;
    constexpr std::uint32_t kNotLoaded = 0xFFFFFFFFu, kEmpty = 0xFFFFFFFEu;
    std::vector<std::uint32_t> meshSlot(model.meshes.size(), kNotLoaded);  // glTF mesh -> Scene mesh
    std::vector<Aabb> meshBounds;
    std::vector<PendingInstance> pending;
    glm::dvec3 lo(std::numeric_limits<double>::max()), hi(-std::numeric_limits<double>::max());
    std::vector<char> visited(model.nodes.size(), 0);
    struct Item {
        int node;
        glm::dmat4 parent;
    };
    std::vector<Item> stack;
    for (auto it = roots.rbegin(); it != roots.rend(); ++it) stack.push_back({*it, glm::dmat4(1.0)});
    while (!stack.empty()) {
        const Item item = stack.back();
        stack.pop_back();
        if (item.node < 0 || static_cast<std::size_t>(item.node) >= model.nodes.size())
            return detail::fileError(path, "node " + std::to_string(item.node) + " does not exist");
        const auto ni = static_cast<std::size_t>(item.node);
        const tinygltf::Node& node = model.nodes[ni];
        const std::string name = nodeName(item.node, node);
        // glTF nodes form a forest: a second visit means a cycle or a shared child.
        if (visited[ni]) return detail::fileError(path, name + " is reached twice (cycle in the node hierarchy)");
        visited[ni] = 1;
        glm::dmat4 local;
        if (auto f = localMatrix(node, local)) return detail::fileError(path, name + ": " + f->what);
        const glm::dmat4 world = item.parent * local;
        if (node.mesh >= 0) {
            if (static_cast<std::size_t>(node.mesh) >= model.meshes.size())
                return detail::fileError(path, name + ": mesh " + std::to_string(node.mesh) + " does not exist");
            std::uint32_t& slot = meshSlot[static_cast<std::size_t>(node.mesh)];
            if (slot == kNotLoaded) {
                Mesh mesh;
                if (auto f = buildMesh(model, node.mesh, mesh)) return detail::fileError(path, f->what);
                if (mesh.indices.empty()) {
                    slot = kEmpty;
                } else {
                    slot = static_cast<std::uint32_t>(scene.meshes.size());
                    meshBounds.push_back(mesh.bounds());
                    scene.meshes.push_back(std::move(mesh));
                }
            }
            if (slot != kEmpty) {
                const Aabb& b = meshBounds[slot];
                for (int corner = 0; corner < 8; ++corner) {
                    const glm::dvec4 p = world * glm::dvec4(corner & 1 ? b.max.x : b.min.x, corner & 2 ? b.max.y : b.min.y,
                                                            corner & 4 ? b.max.z : b.min.z, 1.0);
                    for (int k = 0; k < 3; ++k)
                        if (!(std::abs(p[k]) <= kMaxWorldCoordinate))  // also catches NaN
                            return detail::fileError(path, name + ": places mesh '" + scene.meshes[slot].name +
                                                               "' beyond the accepted world range (|coordinate| <= 1e15)");
                    lo = glm::min(lo, glm::dvec3(p));
                    hi = glm::max(hi, glm::dvec3(p));
                }
                pending.push_back({slot, world, item.node});
            }
        }
        for (auto c = node.children.rbegin(); c != node.children.rend(); ++c) stack.push_back({*c, world});
    }
    if (pending.empty()) return detail::fileError(path, "the scene has no node with a triangle mesh");

    const glm::dvec3 centre = (lo + hi) * 0.5;
    if (glm::length(centre) > kRecentreRatio * glm::length(hi - lo) * 0.5) scene.origin = centre;
    scene.instances.reserve(pending.size());
    for (const PendingInstance& p : pending) {
        glm::dmat4 relative = p.world;
        relative[3] -= glm::dvec4(scene.origin, 0.0);
        const glm::mat4 transform(relative);
        const tinygltf::Node& node = model.nodes[static_cast<std::size_t>(p.node)];
        if (Status s = validateMatrix(transform); !s)
            return detail::fileError(path, nodeName(p.node, node) + ": " + s.message());
        scene.instances.push_back(Instance{p.mesh, transform, node.name.empty() ? "node " + std::to_string(p.node) : node.name});
    }
    return scene;
}

}  // namespace

Expected<Scene> loadGltf(const std::filesystem::path& path) {
    try {
        return loadGltfImpl(path);
    } catch (const std::exception& e) {
        return detail::fileError(path, std::string("cannot load: ") + e.what());
    }
}

}  // namespace dyncull
