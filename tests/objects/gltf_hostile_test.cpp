// Hostile glTF input (issue 19): out-of-range offsets, lengths, strides and counts,
// deep JSON nesting, GLB headers, required extensions, buffer URIs, node matrices and
// far-from-origin scenes. Every case must be an Error naming the file and the field.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <sys/stat.h>

#include <glm/gtc/matrix_transform.hpp>
#include <gtest/gtest.h>

#include "dyncull/loaders/loaders.hpp"
#include "objects/test_files.hpp"

namespace dyncull {
namespace {

using test::put;
using test::TempDir;
using test::expectError;
using test::base64;

constexpr const char* k2to64minus1 = "18446744073709551615";

// 44 bytes: a triangle (0,0,0) (1,0,0) (0,1,0) as float VEC3, uint16 indices 0 1 2, 2 bytes padding.
std::string triangleBytes() {
    std::string b;
    for (float f : {0.f, 0.f, 0.f, 1.f, 0.f, 0.f, 0.f, 1.f, 0.f}) put<float>(b, f, false);
    for (std::uint16_t i : {0, 1, 2}) put<std::uint16_t>(b, i, false);
    put<std::uint16_t>(b, 0, false);
    return b;
}

// A one-triangle glTF whose parts the tests replace.
struct Doc {
    std::string bufferView0 = R"("buffer": 0, "byteOffset": 0, "byteLength": 36)";
    std::string bufferView1 = R"("buffer": 0, "byteOffset": 36, "byteLength": 6)";
    std::string accessor0 = R"("bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3")";
    std::string accessor1 = R"("bufferView": 1, "componentType": 5123, "count": 3, "type": "SCALAR")";
    std::string primitive = R"("attributes": {"POSITION": 0}, "indices": 1)";
    std::string nodes = R"([{"name": "tri", "mesh": 0}])";
    std::string top;  ///< extra top-level members, each ending with a comma
    std::string buffer = R"("byteLength": 44, "uri": "data:application/octet-stream;base64,)" + base64(triangleBytes()) + "\"";

    std::string json() const {
        return "{" + top + R"("asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}], "nodes": )" + nodes +
               R"(, "meshes": [{"name": "m", "primitives": [{)" + primitive + R"(}]}], "buffers": [{)" + buffer +
               R"(}], "bufferViews": [{)" + bufferView0 + "}, {" + bufferView1 + R"(}], "accessors": [{)" + accessor0 +
               "}, {" + accessor1 + "}]}";
    }
};

Expected<Scene> load(const TempDir& dir, const Doc& d, std::filesystem::path& path) {
    path = dir.write("t.gltf", d.json());
    return loadGltf(path);
}

TEST(GltfHostile, BaselineDocLoads) {
    TempDir dir;
    std::filesystem::path path;
    auto r = load(dir, Doc{}, path);
    ASSERT_TRUE(r.ok()) << r.error().message;
    ASSERT_EQ(r->instances.size(), 1u);
    EXPECT_EQ(r->meshes[0].triangleCount(), 1u);
    EXPECT_EQ(r->origin, glm::dvec3(0.0));
}

// ---- 1. offsets, lengths, strides and counts ------------------------------------------

struct FieldCase {
    std::string value;
    std::string expect;
};

void runBufferViewCases(const std::string& field, const std::vector<FieldCase>& cases, bool index) {
    for (const FieldCase& c : cases) {
        SCOPED_TRACE(field + " = " + c.value);
        TempDir dir;
        Doc d;
        std::string& bv = index ? d.bufferView1 : d.bufferView0;
        if (field == "byteOffset") bv = R"("buffer": 0, "byteLength": 36, "byteOffset": )" + c.value;
        else if (field == "byteLength") bv = R"("buffer": 0, "byteOffset": 8, "byteLength": )" + c.value;
        else bv = R"("buffer": 0, "byteOffset": 0, "byteLength": 36, "byteStride": )" + c.value;
        std::filesystem::path path;
        expectError(load(dir, d, path), path, c.expect);
    }
}

TEST(GltfHostile, BufferViewByteOffsetOverflow) {
    // 2^64 - 8 + 36 wraps to 28: the old check passed and read 8 bytes before the buffer.
    runBufferViewCases("byteOffset",
                       {{k2to64minus1, "bufferView 0: byteOffset 18446744073709551615 is past the end of buffer 0 (44 bytes)"},
                        {"18446744073709551608", "bufferView 0: byteOffset 18446744073709551608 is past the end"},
                        {"18446744073709551580", "bufferView 0: byteOffset"},
                        {"4294967295", "bufferView 0: byteOffset 4294967295"},
                        {"4294967296", "bufferView 0: byteOffset 4294967296"},
                        {"9007199254740993", "bufferView 0: byteOffset 9007199254740993"},  // 2^53 + 1 arrives exactly
                        {"9", "bufferView 0: byteLength 36 at byteOffset 9 reads past the end of buffer 0"}},
                       false);
}

TEST(GltfHostile, BufferViewByteLengthOverflow) {
    runBufferViewCases("byteLength",
                       {{k2to64minus1, "bufferView 0: byteLength 18446744073709551615 at byteOffset 8"},
                        {"18446744073709551608", "bufferView 0: byteLength 18446744073709551608"},  // 8 + it wraps to 0
                        {"4294967296", "bufferView 0: byteLength 4294967296"},
                        {"4294967288", "bufferView 0: byteLength 4294967288"},
                        {"18446744073709551616", "byteLength"}},  // 2^64 is no integer for tinygltf: rejected as required field
                       false);
}

TEST(GltfHostile, BufferViewByteStrideOutOfSpec) {
    runBufferViewCases("byteStride",
                       {{"4", "bufferView 0: byteStride 4 is smaller than the 12-byte elements of accessor 0"},
                        {"2", "byteStride"},  // tinygltf: not a multiple of 4
                        {"256", "byteStride"},
                        {"4294967296", "byteStride"},
                        {"4294967300", "byteStride"},
                        {"18446744073709551612", "byteStride"},
                        {"252", "accessor 0: count 3 (stride 252, byteOffset 0) reads past the end of bufferView 0"}},
                       false);
}

TEST(GltfHostile, IndexBufferViewOverflow) {
    runBufferViewCases("byteOffset",
                       {{"18446744073709551580", "bufferView 1: byteOffset"}, {k2to64minus1, "bufferView 1: byteOffset"}},
                       true);
    runBufferViewCases("byteLength", {{"18446744073709551608", "bufferView 1: byteLength"}}, true);
    runBufferViewCases("byteStride", {{"4294967296", "byteStride"}}, true);
}

void runAccessorCases(const std::string& field, const std::vector<FieldCase>& cases, bool index) {
    for (const FieldCase& c : cases) {
        SCOPED_TRACE(field + " = " + c.value);
        TempDir dir;
        Doc d;
        const std::string head = index ? R"("bufferView": 1, "componentType": 5123, "type": "SCALAR", )"
                                       : R"("bufferView": 0, "componentType": 5126, "type": "VEC3", )";
        std::string& a = index ? d.accessor1 : d.accessor0;
        if (field == "byteOffset") a = head + R"("count": 3, "byteOffset": )" + c.value;
        else a = head + R"("count": )" + c.value;
        std::filesystem::path path;
        expectError(load(dir, d, path), path, c.expect);
    }
}

TEST(GltfHostile, AccessorByteOffsetOverflow) {
    runAccessorCases("byteOffset",
                     {{k2to64minus1, "POSITION accessor 0: byteOffset 18446744073709551615 is past the end of bufferView 0 (36 bytes)"},
                      {"18446744073709551604", "accessor 0: byteOffset 18446744073709551604"},  // + 12 wraps to 0
                      {"4294967296", "accessor 0: byteOffset 4294967296"},
                      {"4294967295", "accessor 0: byteOffset 4294967295"},
                      {"36", "accessor 0: count 3 (stride 12, byteOffset 36) reads past the end of bufferView 0"},
                      {"4", "accessor 0: count 3 (stride 12, byteOffset 4) reads past the end"}},
                     false);
}

TEST(GltfHostile, AccessorCountOverflow) {
    runAccessorCases("count",
                     {{k2to64minus1, "POSITION accessor 0: count 18446744073709551615"},
                      {"1537228672809129302", "accessor 0: count 1537228672809129302"},  // 12 * (count - 1) + 12 wraps to 0
                      {"4611686018427387905", "accessor 0: count 4611686018427387905"},  // 2^62 + 1
                      {"4294967296", "accessor 0: count 4294967296"},
                      {"357913942", "accessor 0: count 357913942"},  // 12 * count just above 2^32
                      {"4", "accessor 0: count 4 (stride 12, byteOffset 0) reads past the end of bufferView 0 (36 bytes)"}},
                     false);
}

TEST(GltfHostile, IndexAccessorOverflow) {
    runAccessorCases("byteOffset", {{k2to64minus1, "indices accessor 1: byteOffset 18446744073709551615"}}, true);
    runAccessorCases("count",
                     {{k2to64minus1, "indices accessor 1: count 18446744073709551615"},
                      {"9223372036854775809", "indices accessor 1: count 9223372036854775809"},  // 2 * (2^63 + 1) wraps to 2
                      {"4294967296", "indices accessor 1: count 4294967296"}},
                     true);
}

// JSON integers of 2^64 and above are not unsigned integers for tinygltf (nlohmann parses
// them as doubles): an optional field then reads as absent, a required one is an error.
// Either way nothing is read out of bounds.
TEST(GltfHostile, SizeFieldsThatAreNotWholeNumbersAreErrors) {
    for (const char* v : {"18446744073709551616", "1e30", "-1", "4.5"}) {
        SCOPED_TRACE(v);
        TempDir dir;
        Doc d;
        d.accessor0 = R"("bufferView": 0, "componentType": 5126, "type": "VEC3", "count": 3, "byteOffset": )" + std::string(v);
        d.bufferView0 = R"("buffer": 0, "byteLength": 36, "byteOffset": )" + std::string(v);
        std::filesystem::path path;
        // tinygltf alone read these optional fields as absent (0): a wrong model, exit 0.
        expectError(load(dir, d, path), path, "bufferViews[0].byteOffset is ");
        d = Doc{};
        d.bufferView0 = R"("buffer": 0, "byteLength": 36, "byteStride": )" + std::string(v);
        expectError(load(dir, d, path), path, "bufferViews[0].byteStride is ");
        d = Doc{};
        d.accessor0 = R"("bufferView": 0, "componentType": 5126, "type": "VEC3", "count": 3, "byteOffset": )" + std::string(v);
        expectError(load(dir, d, path), path, "accessors[0].byteOffset is ");
        d = Doc{};
        d.accessor0 = R"("bufferView": 0, "componentType": 5126, "type": "VEC3", "count": )" + std::string(v);
        expectError(load(dir, d, path), path, "count");
    }
}

// ---- 2. JSON nesting ------------------------------------------------------------------

std::string nested(std::size_t depth, const std::string& open, const std::string& close) {
    std::string s;
    for (std::size_t i = 0; i < depth; ++i) s += open;
    s += "0";
    for (std::size_t i = 0; i < depth; ++i) s += close;
    return s;
}

TEST(GltfHostile, DeepNestingIsRejectedBeforeParsing) {
    TempDir dir;
    const struct {
        const char* what;
        std::string open, close;
    } kinds[] = {{"arrays", "[", "]"}, {"objects", R"({"a":)", "}"}, {"mixed", R"([{"a":)", "}]"}};
    for (const auto& k : kinds) {
        SCOPED_TRACE(k.what);
        Doc d;
        d.top = R"("extras": )" + nested(15000, k.open, k.close) + ",";
        std::filesystem::path path;
        expectError(load(dir, d, path), path, "JSON nests deeper than 64 levels");
    }
    // 63 levels inside the top-level object (64 in all) are accepted; one more is not.
    Doc ok;
    ok.top = R"("extras": )" + nested(63, "[", "]") + ",";
    std::filesystem::path path;
    auto r = load(dir, ok, path);
    EXPECT_TRUE(r.ok()) << r.error().message;
    Doc deep;
    deep.top = R"("extras": )" + nested(64, "[", "]") + ",";
    expectError(load(dir, deep, path), path, "JSON nests deeper than 64 levels");
}

TEST(GltfHostile, BracketsInsideStringsDoNotCount) {
    TempDir dir;
    Doc d;
    // Thousands of brackets, an escaped quote and an escaped backslash before the closing quote.
    d.nodes = R"([{"name": "[[[{{{\"[[[\\", "mesh": 0, "extras": {"s": ")" + std::string(5000, '[') +
              std::string(5000, '{') + R"(\\\"]]]"}}])";
    std::filesystem::path path;
    auto r = load(dir, d, path);
    ASSERT_TRUE(r.ok()) << r.error().message;
    EXPECT_EQ(r->instances[0].name, "[[[{{{\"[[[\\");
}

std::string glbFile(std::string json, std::string bin, std::uint32_t version = 2, std::int64_t binLengthDelta = 0) {
    while (json.size() % 4) json += ' ';
    while (bin.size() % 4) bin += '\0';
    std::string glb;
    put<std::uint32_t>(glb, 0x46546C67u, false);  // "glTF"
    put<std::uint32_t>(glb, version, false);
    put<std::uint32_t>(glb, static_cast<std::uint32_t>(12 + 8 + json.size() + 8 + bin.size()), false);
    put<std::uint32_t>(glb, static_cast<std::uint32_t>(json.size()), false);
    put<std::uint32_t>(glb, 0x4E4F534Au, false);  // "JSON"
    glb += json;
    put<std::uint32_t>(glb, static_cast<std::uint32_t>(static_cast<std::int64_t>(bin.size()) + binLengthDelta), false);
    put<std::uint32_t>(glb, 0x004E4942u, false);  // "BIN\0"
    glb += bin;
    return glb;
}

Doc glbDoc() {
    Doc d;
    d.buffer = R"("byteLength": 44)";
    return d;
}

TEST(GltfHostile, GlbBaselineLoads) {
    TempDir dir;
    const auto path = dir.write("t.glb", glbFile(glbDoc().json(), triangleBytes()));
    auto r = loadGltf(path);
    ASSERT_TRUE(r.ok()) << r.error().message;
    EXPECT_EQ(r->instances.size(), 1u);
}

TEST(GltfHostile, GlbDeepJsonChunkIsRejected) {
    TempDir dir;
    Doc d = glbDoc();
    d.top = R"("extras": )" + nested(15000, "[", "]") + ",";
    const auto path = dir.write("deep.glb", glbFile(d.json(), triangleBytes()));
    expectError(loadGltf(path), path, "JSON nests deeper than 64 levels");
}

// ---- 3. spec leniency -----------------------------------------------------------------

TEST(GltfHostile, GlbVersionOtherThan2IsRejected) {
    TempDir dir;
    for (std::uint32_t v : {0u, 1u, 3u, 0xFFFFFFFFu}) {
        SCOPED_TRACE(v);
        const auto path = dir.write("v.glb", glbFile(glbDoc().json(), triangleBytes(), v));
        expectError(loadGltf(path), path, "GLB version " + std::to_string(v) + " is not supported (only version 2)");
    }
}

TEST(GltfHostile, GlbChunkLengthsMustFitTheFile) {
    TempDir dir;
    // tinygltf accepted a BIN chunk ending up to 8 bytes past the file.
    auto path = dir.write("bin8.glb", glbFile(glbDoc().json(), triangleBytes(), 2, 8));
    expectError(loadGltf(path), path, "GLB BIN chunk length 52 runs past the end of the file");
    path = dir.write("binhuge.glb", glbFile(glbDoc().json(), triangleBytes(), 2, 0xFFFFFFF0 - 44));
    expectError(loadGltf(path), path, "GLB BIN chunk length");
    std::string glb = glbFile(glbDoc().json(), triangleBytes());
    glb[12] = '\xF0';  // JSON chunk length far beyond the file
    glb[13] = '\xFF';
    glb[14] = '\xFF';
    glb[15] = '\xFF';
    path = dir.write("json.glb", glb);
    expectError(loadGltf(path), path, "GLB JSON chunk length");
    glb = glbFile(glbDoc().json(), triangleBytes());
    path = dir.write("cut.glb", glb.substr(0, glb.size() - 4));
    expectError(loadGltf(path), path, "exceeds the file size");
    path = dir.write("short.glb", glb.substr(0, 19));
    expectError(loadGltf(path), path, "shorter than its 20-byte header");
}

TEST(GltfHostile, UnknownRequiredExtensionIsRejected) {
    TempDir dir;
    Doc d;
    d.top = R"("extensionsUsed": ["EXT_meshopt_compression"], "extensionsRequired": ["EXT_meshopt_compression"],)";
    std::filesystem::path path;
    expectError(load(dir, d, path), path, "requires the unsupported extension EXT_meshopt_compression");
    d.top = R"("extensionsUsed": ["EXT_future"], "extensionsRequired": ["KHR_materials_unlit", "EXT_future"],)";
    expectError(load(dir, d, path), path, "requires the unsupported extension EXT_future");
    // Extensions that change only materials, textures or allowed component types are fine.
    d.top = R"("extensionsUsed": ["KHR_materials_unlit", "KHR_mesh_quantization", "KHR_texture_transform"],
               "extensionsRequired": ["KHR_materials_unlit", "KHR_mesh_quantization", "KHR_texture_transform"],)";
    auto r = load(dir, d, path);
    EXPECT_TRUE(r.ok()) << r.error().message;
    // Used but not required: the file must be readable without it.
    d.top = R"("extensionsUsed": ["EXT_future"],)";
    r = load(dir, d, path);
    EXPECT_TRUE(r.ok()) << r.error().message;
}

TEST(GltfHostile, DracoFileSaysHowToDecompress) {
    TempDir dir;
    Doc d;
    // As Draco exporters write it: accessors without bufferViews, the data in the extension.
    d.accessor0 = R"("componentType": 5126, "count": 3, "type": "VEC3")";
    d.accessor1 = R"("componentType": 5123, "count": 3, "type": "SCALAR")";
    d.primitive = R"("attributes": {"POSITION": 0}, "indices": 1,
                     "extensions": {"KHR_draco_mesh_compression": {"bufferView": 0, "attributes": {"POSITION": 0}}})";
    d.top = R"("extensionsUsed": ["KHR_draco_mesh_compression"], "extensionsRequired": ["KHR_draco_mesh_compression"],)";
    std::filesystem::path path;
    expectError(load(dir, d, path), path, "Draco-compressed");
    expectError(load(dir, d, path), path, "npx @gltf-transform/cli copy in.glb out.glb");
    // Not listed as required (an invalid file, but seen): still named.
    d.top = R"("extensionsUsed": ["KHR_draco_mesh_compression"],)";
    expectError(load(dir, d, path), path, "the geometry is Draco-compressed");
    d.primitive = R"("attributes": {"POSITION": 0},
                     "extensions": {"KHR_draco_mesh_compression": {"bufferView": 0, "attributes": {"POSITION": 0}}})";
    expectError(load(dir, d, path), path, "mesh 0 primitive 0: the geometry is Draco-compressed");
    // Used with an uncompressed fallback: loads the fallback.
    Doc fallback;
    fallback.primitive = d.primitive;
    fallback.top = d.top;
    auto r = load(dir, fallback, path);
    EXPECT_TRUE(r.ok()) << r.error().message;
}

// ---- 4. buffer URIs -------------------------------------------------------------------

TEST(GltfHostile, BufferUriNotARegularFile) {
    TempDir dir;
    std::filesystem::create_directory(dir.file("sub"));
    ASSERT_EQ(::mkfifo(dir.file("fifo").c_str(), 0600), 0);  // opening it would block forever
    std::filesystem::create_symlink("/dev/zero", dir.file("zero"));
    for (const char* uri : {".", "..", "sub", "sub/", "fifo", "zero"}) {
        SCOPED_TRACE(uri);
        Doc d;
        d.buffer = R"("byteLength": 44, "uri": ")" + std::string(uri) + "\"";
        std::filesystem::path path;
        expectError(load(dir, d, path), path, "not a regular file");
    }
    // Absolute paths are joined to the file's directory by tinygltf, so they are not found.
    Doc d;
    d.buffer = R"("byteLength": 44, "uri": "/dev/zero")";
    std::filesystem::path path;
    expectError(load(dir, d, path), path, "/dev/zero");
}

TEST(GltfHostile, BufferUriEmptyOrMissing) {
    TempDir dir;
    Doc d;
    d.buffer = R"("byteLength": 44, "uri": "")";
    std::filesystem::path path;
    expectError(load(dir, d, path), path, "uri");
    d.buffer = R"("byteLength": 44)";
    expectError(load(dir, d, path), path, "uri");
    d.buffer = R"("byteLength": 44, "uri": "missing.bin")";
    expectError(load(dir, d, path), path, "missing.bin");
}

// ---- 5. precision far from the origin ------------------------------------------------

TEST(GltfPrecision, FourInstancesUnder1e8RootStayTwoUnitsApart) {
    TempDir dir;
    Doc d;
    d.nodes = R"([{"name": "root", "translation": [1e8, 0, 0], "children": [1, 2, 3, 4]},
                 {"mesh": 0, "translation": [0, 0, 0]}, {"mesh": 0, "translation": [2, 0, 0]},
                 {"mesh": 0, "translation": [4, 0, 0]}, {"mesh": 0, "translation": [6, 0, 0]}])";
    std::filesystem::path path;
    auto r = load(dir, d, path);
    ASSERT_TRUE(r.ok()) << r.error().message;
    ASSERT_EQ(r->instances.size(), 4u);
    EXPECT_NE(r->origin, glm::dvec3(0.0));
    for (std::size_t i = 0; i < 4; ++i) {
        const glm::mat4& t = r->instances[i].transform;
        EXPECT_EQ(r->origin.x + static_cast<double>(t[3].x), 1e8 + 2.0 * static_cast<double>(i)) << i;
        EXPECT_EQ(r->origin.y + static_cast<double>(t[3].y), 0.0);
        if (i > 0) {
            EXPECT_EQ(t[3].x - r->instances[i - 1].transform[3].x, 2.0f) << i;
        }
        EXPECT_EQ(glm::mat3(t), glm::mat3(1.0f));
    }
    // The stored (relative) coordinates are small: the scene is centred on its origin.
    EXPECT_LT(std::abs(r->worldBounds().center().x), 1.0f);
}

// Compares every instance of `far` (a copy of `near` moved by `offset`) with `near`, in
// world space, to `tol` per matrix element.
void expectSamePlacement(const Scene& near, const Scene& far, const glm::dvec3& offset, double tol) {
    ASSERT_EQ(near.instances.size(), far.instances.size());
    const glm::dvec3 shift = far.origin - offset - near.origin;  // far's relative frame in near's relative frame
    for (std::size_t i = 0; i < near.instances.size(); ++i) {
        const glm::dmat4 a(near.instances[i].transform);
        glm::dmat4 b(far.instances[i].transform);
        b[3] += glm::dvec4(shift, 0.0);
        for (int c = 0; c < 4; ++c)
            for (int k = 0; k < 4; ++k) EXPECT_NEAR(a[c][k], b[c][k], tol) << "instance " << i << " [" << c << "][" << k << "]";
    }
}

TEST(GltfPrecision, HierarchyFarFromOriginMatchesTheSameAtTheOrigin) {
    TempDir dir;
    const std::string children = R"(
        {"name": "arm", "translation": [3.25, -1.5, 7], "rotation": [0.1825742, 0.3651484, 0.5477226, 0.7302967],
         "scale": [0.5, 2, 1.5], "children": [2, 3]},
        {"name": "a", "mesh": 0, "matrix": [0,1,0,0, -1,0,0,0, 0,0,1,0, 0.125,4.5,-2,1]},
        {"name": "b", "mesh": 0, "translation": [-6, 0.75, 3], "rotation": [0, 0.7071068, 0, 0.7071068]})";
    Doc nearDoc, farDoc;
    nearDoc.nodes = R"([{"name": "root", "children": [1]},)" + children + "]";
    const glm::dvec3 offset(1e7, -3e6, 2.5e7);
    farDoc.nodes = R"([{"name": "root", "translation": [1e7, -3e6, 2.5e7], "children": [1]},)" + children + "]";
    std::filesystem::path path;
    auto near = load(dir, nearDoc, path);
    ASSERT_TRUE(near.ok()) << near.error().message;
    EXPECT_EQ(near->origin, glm::dvec3(0.0));  // close to the origin: no recentring
    auto far = load(dir, farDoc, path);
    ASSERT_TRUE(far.ok()) << far.error().message;
    EXPECT_GT(glm::length(far->origin), 1e7);
    // Float round-off of values of size ~10 only (composing in float left errors of ~1 unit).
    expectSamePlacement(*near, *far, offset, 1e-5);
}

// Index just past the JSON value (array/object) that opens at `open`; strings respected.
std::size_t endOfValue(const std::string& s, std::size_t open) {
    int depth = 0;
    bool inString = false;
    for (std::size_t i = open; i < s.size(); ++i) {
        const char c = s[i];
        if (inString) {
            if (c == '\\') ++i;
            else if (c == '"') inString = false;
        } else if (c == '"') {
            inString = true;
        } else if (c == '[' || c == '{') {
            ++depth;
        } else if ((c == ']' || c == '}') && --depth == 0) {
            return i + 1;
        }
    }
    return std::string::npos;
}

// Number of top-level elements of the array opening at `open`.
std::size_t arrayLength(const std::string& s, std::size_t open) {
    std::size_t n = 0;
    for (std::size_t i = open + 1; i < s.size();) {
        while (i < s.size() && (s[i] == ' ' || s[i] == '\n' || s[i] == '\r' || s[i] == '\t' || s[i] == ',')) ++i;
        if (s[i] == ']') return n;
        ++n;
        i = s[i] == '{' || s[i] == '[' ? endOfValue(s, i) : s.find_first_of(",]", i);
    }
    return n;
}

// The real 2CylinderEngine (skipped when ../shared/data is absent) under a root moved by
// 1e7: the loader's placements must match the original's to float round-off of the
// model's own size (composed in float they were off by up to a unit, 3% of the pixels).
TEST(GltfPrecision, TwoCylinderEngineAt1e7MatchesTheOriginal) {
    std::filesystem::path data = DYNCULL_SHARED_DATA_DIR;
    if (const char* env = std::getenv("DYNCULL_DATA"); env && *env) data = env;
    const auto original = data / "2CylinderEngine.gltf";
    if (!std::filesystem::exists(original) || !std::filesystem::exists(data / "2CylinderEngine0.bin"))
        GTEST_SKIP() << original << " not available";
    std::stringstream ss;
    ss << std::ifstream(original).rdbuf();
    std::string json = ss.str();
    // scenes[0].nodes -> [new root]; the new root (appended to "nodes") holds the old roots.
    const std::size_t scenes = json.find("\"scenes\"");
    const std::size_t rootsOpen = json.find('[', json.find("\"nodes\"", scenes));
    const std::size_t rootsEnd = endOfValue(json, rootsOpen);
    const std::string oldRoots = json.substr(rootsOpen + 1, rootsEnd - rootsOpen - 2);
    const std::size_t nodesOpen = json.find('[', json.find("\"nodes\"", rootsEnd));
    const std::size_t newRoot = arrayLength(json, nodesOpen);
    const std::size_t nodesEnd = endOfValue(json, nodesOpen);
    ASSERT_NE(nodesEnd, std::string::npos);
    json.insert(nodesEnd - 1, R"(, {"name": "far", "translation": [1e7, 0, 0], "children": [)" + oldRoots + "]}");
    json.replace(rootsOpen + 1, rootsEnd - rootsOpen - 2, std::to_string(newRoot));

    TempDir dir;
    std::filesystem::create_symlink(data / "2CylinderEngine0.bin", dir.file("2CylinderEngine0.bin"));
    const auto farPath = dir.write("far.gltf", json);
    auto near = loadGltf(original);
    ASSERT_TRUE(near.ok()) << near.error().message;
    auto far = loadGltf(farPath);
    ASSERT_TRUE(far.ok()) << far.error().message;
    EXPECT_EQ(near->origin, glm::dvec3(0.0));
    EXPECT_GT(far->origin.x, 1e7 - 1e4);
    const double radius = 0.5 * static_cast<double>(glm::length(near->worldBounds().extent()));
    RecordProperty("radius", static_cast<int>(radius));
    expectSamePlacement(*near, *far, glm::dvec3(1e7, 0, 0), std::max(1e-6, 1e-6 * radius));
}

// ---- 6. degenerate node matrices ----------------------------------------------------

TEST(GltfHostile, NonAffineNodeMatrixIsRejected) {
    TempDir dir;
    for (const char* bottom : {"0,0,0,0", "0,0,0,2", "0.001,0,0,1", "0,0,-1e-6,1"}) {
        SCOPED_TRACE(bottom);
        Doc d;
        // glTF is column-major: the bottom row is element 3 of each column.
        const std::string m = bottom;
        std::vector<std::string> v;
        for (std::size_t s = 0, e; s <= m.size(); s = e + 1) {
            e = m.find(',', s);
            if (e == std::string::npos) e = m.size();
            v.push_back(m.substr(s, e - s));
        }
        d.nodes = R"([{"name": "proj", "mesh": 0, "matrix": [1,0,0,)" + v[0] + ", 0,1,0," + v[1] + ", 0,0,1," + v[2] +
                  ", 5,6,7," + v[3] + "]}]";
        std::filesystem::path path;
        expectError(load(dir, d, path), path, "node 0 ('proj'): matrix is not affine");
    }
    Doc wrongSize;
    wrongSize.nodes = R"([{"name": "short", "mesh": 0, "matrix": [1,0,0,0, 0,1,0,0, 0,0,1,0, 0,0,0]}])";
    std::filesystem::path path;
    expectError(load(dir, wrongSize, path), path, "node 0 ('short'): matrix has 15 elements, expected 16");
    wrongSize.nodes = R"([{"mesh": 0, "translation": [1, 2]}])";
    expectError(load(dir, wrongSize, path), path, "node 0: translation has 2 elements, expected 3");
}

TEST(GltfHostile, WorldCoordinatesBeyondRangeAreRejected) {
    TempDir dir;
    std::filesystem::path path;
    const struct {
        const char* nodes;
        const char* expect;  // nullptr: loads
    } cases[] = {
        {R"([{"name": "huge", "scale": [1e30, 1e30, 1e30], "children": [1]}, {"name": "t", "mesh": 0}])",
         "node 1 ('t'): places mesh 'm' beyond the accepted world range"},
        {R"([{"name": "far", "translation": [0, 2e15, 0], "mesh": 0}])", "node 0 ('far'): places mesh 'm' beyond"},
        {R"([{"name": "inf", "translation": [0, 1e400, 0], "mesh": 0}])", "1e400"},  // the JSON parser refuses it
        {R"([{"name": "nan", "scale": [1e300, 1e300, 1e300], "children": [1]}, {"scale": [1e300, 0, 1], "mesh": 0}])",
         "node 1"},
        {R"([{"name": "tiny", "scale": [1e-30, 1e-30, 1e-30], "mesh": 0}])", "node 0 ('tiny'): transform matrix is singular"},
        {R"([{"name": "big", "translation": [9e14, 0, 0], "mesh": 0}])", nullptr},
        {R"([{"name": "bigscale", "scale": [1e14, 1e14, 1e14], "mesh": 0}])", nullptr},
    };
    for (const auto& c : cases) {
        SCOPED_TRACE(c.nodes);
        Doc d;
        d.nodes = c.nodes;
        auto r = load(dir, d, path);
        if (c.expect) expectError(r, path, c.expect);
        else EXPECT_TRUE(r.ok()) << r.error().message;
    }
}

}  // namespace
}  // namespace dyncull
