// fuzz_make_seeds DIR: writes small valid files of every text-based format the loaders
// read into DIR/gltf, DIR/glb, DIR/ply and DIR/obj, the seed corpora of scripts/fuzz.sh
// (issue 19). Valid files reach the deep code paths at once, so the structure-aware
// mutator starts from real bufferViews, accessors, PLY headers and OBJ faces; generating
// them here keeps binary seeds out of the repository and needs no ./build test run.
// Every seed is loaded back: a seed the loaders reject (after a loader change) fails here
// instead of silently shrinking what the fuzzers start from.
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>

#include "dyncull/loaders/loaders.hpp"

namespace {

namespace fs = std::filesystem;

template <class T>
void put(std::string& out, T v, bool bigEndian = false) {
    unsigned char b[sizeof(T)];
    std::memcpy(b, &v, sizeof(T));
    if (bigEndian)
        for (std::size_t i = 0; i < sizeof(T) / 2; ++i) std::swap(b[i], b[sizeof(T) - 1 - i]);
    out.append(reinterpret_cast<const char*>(b), sizeof(T));
}

std::string base64(const std::string& in) {
    static constexpr char kAlphabet[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    std::string out;
    for (std::size_t i = 0; i < in.size(); i += 3) {
        std::uint32_t v = static_cast<unsigned char>(in[i]) << 16;
        if (i + 1 < in.size()) v |= static_cast<unsigned char>(in[i + 1]) << 8;
        if (i + 2 < in.size()) v |= static_cast<unsigned char>(in[i + 2]);
        out += kAlphabet[(v >> 18) & 63];
        out += kAlphabet[(v >> 12) & 63];
        out += i + 1 < in.size() ? kAlphabet[(v >> 6) & 63] : '=';
        out += i + 2 < in.size() ? kAlphabet[v & 63] : '=';
    }
    return out;
}

// A unit quad: 4 interleaved position+normal vertices (96 bytes, stride 24), then u16
// list indices (12), u8 strip indices (4) and u32 indices of one triangle (12): 124 bytes.
std::string quadBuffer() {
    std::string b;
    const float xy[4][2] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
    for (const auto& p : xy) {
        for (float f : {p[0], p[1], 0.0f, 0.0f, 0.0f, 1.0f}) put<float>(b, f);
    }
    for (std::uint16_t i : {0, 1, 2, 0, 2, 3}) put<std::uint16_t>(b, i);
    for (std::uint8_t i : {0, 1, 3, 2}) put<std::uint8_t>(b, i);
    for (std::uint32_t i : {0u, 1u, 2u}) put<std::uint32_t>(b, i);
    return b;
}

// A node hierarchy over quadBuffer() using every index width, a strided and a tight
// bufferView, accessor byteOffsets, TRS and matrix transforms, a strip, and extras.
// `bufferUri` empty: the GLB BIN chunk.
std::string hierarchyJson(const std::string& bufferUri) {
    const std::string uri = bufferUri.empty() ? "" : R"(, "uri": ")" + bufferUri + "\"";
    return R"({
  "asset": {"version": "2.0", "generator": "dyncull fuzz_make_seeds"},
  "scene": 0,
  "scenes": [{"nodes": [0]}],
  "nodes": [
    {"name": "root", "translation": [10, 0, 0], "children": [1, 2]},
    {"name": "a", "mesh": 0, "scale": [2, 2, 2]},
    {"name": "b", "mesh": 0, "matrix": [1,0,0,0, 0,1,0,0, 0,0,1,0, 0,5,0,1], "children": [3]},
    {"name": "c", "mesh": 1, "rotation": [0, 0, 0.70710678, 0.70710678], "extras": {"tag": [1, 2, {"k": 3}]}}
  ],
  "meshes": [
    {"name": "quad", "primitives": [
      {"attributes": {"POSITION": 0, "NORMAL": 1}, "indices": 2, "mode": 4},
      {"attributes": {"POSITION": 0, "NORMAL": 1}, "indices": 3, "mode": 5}
    ]},
    {"name": "tri", "primitives": [{"attributes": {"POSITION": 0}, "indices": 4}]}
  ],
  "buffers": [{"byteLength": 124)" + uri + R"(}],
  "bufferViews": [
    {"buffer": 0, "byteOffset": 0, "byteLength": 96, "byteStride": 24, "target": 34962},
    {"buffer": 0, "byteOffset": 96, "byteLength": 12, "target": 34963},
    {"buffer": 0, "byteOffset": 108, "byteLength": 4},
    {"buffer": 0, "byteOffset": 112, "byteLength": 12}
  ],
  "accessors": [
    {"bufferView": 0, "byteOffset": 0, "componentType": 5126, "count": 4, "type": "VEC3", "min": [0,0,0], "max": [1,1,0]},
    {"bufferView": 0, "byteOffset": 12, "componentType": 5126, "count": 4, "type": "VEC3"},
    {"bufferView": 1, "byteOffset": 0, "componentType": 5123, "count": 6, "type": "SCALAR"},
    {"bufferView": 2, "componentType": 5121, "count": 4, "type": "SCALAR"},
    {"bufferView": 3, "componentType": 5125, "count": 3, "type": "SCALAR"}
  ]
})";
}

// The smallest useful file: one non-indexed triangle, one bufferView, no nodes.
std::string triangleBuffer() {
    std::string b;
    for (float f : {0.0f, 0.0f, 0.0f, 1.0f, 0.0f, 0.0f, 0.0f, 1.0f, 0.0f}) put<float>(b, f);
    return b;
}

std::string triangleJson(const std::string& bufferUri) {
    const std::string uri = bufferUri.empty() ? "" : R"(, "uri": ")" + bufferUri + "\"";
    return R"({"asset": {"version": "2.0"}, "meshes": [{"primitives": [{"attributes": {"POSITION": 0}}]}],
 "nodes": [{"mesh": 0}], "buffers": [{"byteLength": 36)" + uri + R"(}],
 "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 36}],
 "accessors": [{"bufferView": 0, "byteOffset": 0, "componentType": 5126, "count": 3, "type": "VEC3"}]})";
}

std::string embedded(const std::string& bytes) { return "data:application/octet-stream;base64," + base64(bytes); }

std::string glb(std::string json, std::string bin) {
    while (json.size() % 4) json += ' ';
    while (bin.size() % 4) bin += '\0';
    std::string out;
    put<std::uint32_t>(out, 0x46546C67u);  // "glTF"
    put<std::uint32_t>(out, 2);
    put<std::uint32_t>(out, static_cast<std::uint32_t>(12 + 8 + json.size() + 8 + bin.size()));
    put<std::uint32_t>(out, static_cast<std::uint32_t>(json.size()));
    put<std::uint32_t>(out, 0x4E4F534Au);  // "JSON"
    out += json;
    put<std::uint32_t>(out, static_cast<std::uint32_t>(bin.size()));
    put<std::uint32_t>(out, 0x004E4942u);  // "BIN\0"
    out += bin;
    return out;
}

// A quad (two faces, one a quad to triangulate) with extra vertex and face properties.
std::string ply(const char* format, bool bigEndian) {
    std::string out = std::string("ply\nformat ") + format +
                      " 1.0\ncomment dyncull fuzz seed\nelement vertex 4\nproperty float x\nproperty float y\n"
                      "property float z\nproperty uchar red\nelement face 2\nproperty list uchar int vertex_indices\n"
                      "property float quality\nend_header\n";
    const float xy[4][2] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
    if (std::strcmp(format, "ascii") == 0) {
        for (const auto& p : xy) out += std::to_string(p[0]) + " " + std::to_string(p[1]) + " 0 255\n";
        out += "3 0 1 2 0.5\n4 0 1 2 3 1\n";
        return out;
    }
    for (const auto& p : xy) {
        put<float>(out, p[0], bigEndian);
        put<float>(out, p[1], bigEndian);
        put<float>(out, 0.0f, bigEndian);
        put<std::uint8_t>(out, 255);
    }
    put<std::uint8_t>(out, 3);
    for (std::int32_t i : {0, 1, 2}) put<std::int32_t>(out, i, bigEndian);
    put<float>(out, 0.5f, bigEndian);
    put<std::uint8_t>(out, 4);
    for (std::int32_t i : {0, 1, 2, 3}) put<std::int32_t>(out, i, bigEndian);
    put<float>(out, 1.0f, bigEndian);
    return out;
}

constexpr const char* kObjQuad = R"(# dyncull fuzz seed
o quad
v 0 0 0
v 1 0 0
v 1 1 0
v 0 1 0
vt 0 0
vt 1 1
vn 0 0 1
g faces
usemtl none
f 1/1/1 2/2/1 3/2/1
f -4//1 -2//1 -1//1
s off
f 1 2 3 4
)";

bool failed = false;

// Writes the seed and checks that `load` accepts it.
template <class Load>
void write(const fs::path& dir, const std::string& name, const std::string& bytes, Load load) {
    fs::create_directories(dir);
    std::ofstream(dir / name, std::ios::binary) << bytes;
    if (auto r = load(dir / name); !r) {
        std::fprintf(stderr, "fuzz_make_seeds: seed %s rejected: %s\n", name.c_str(), r.error().message.c_str());
        failed = true;
    }
}

}  // namespace

int main(int argc, char** argv) {
    if (argc != 2) {
        std::fprintf(stderr, "usage: %s DIR\n", argv[0]);
        return 2;
    }
    using dyncull::loadGltf, dyncull::loadObj, dyncull::loadPly;
    const fs::path out = argv[1];
    write(out / "gltf", "hierarchy.gltf", hierarchyJson(embedded(quadBuffer())), loadGltf);
    write(out / "gltf", "triangle.gltf", triangleJson(embedded(triangleBuffer())), loadGltf);
    write(out / "glb", "hierarchy.glb", glb(hierarchyJson(""), quadBuffer()), loadGltf);
    write(out / "glb", "triangle.glb", glb(triangleJson(""), triangleBuffer()), loadGltf);
    write(out / "ply", "ascii.ply", ply("ascii", false), loadPly);
    write(out / "ply", "le.ply", ply("binary_little_endian", false), loadPly);
    write(out / "ply", "be.ply", ply("binary_big_endian", true), loadPly);
    write(out / "obj", "quad.obj", kObjQuad, loadObj);
    return failed ? 1 : 0;
}
