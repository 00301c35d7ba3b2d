// compactLeaf / expandLeaf (compact_leaf.hpp). Octahedral normals: the unit sphere folded onto
// the octahedron |x| + |y| + |z| = 1 and that unfolded onto the square [-1, 1]^2, as in
// "A Survey of Efficient Representations for Independent Unit Vectors" (Cigolle et al.,
// JCGT 2014), where 16 bits a component keep the error under 0.01 degrees.
#include "dyncull/streaming/compact_leaf.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>

#include "dyncull/streaming/streamed_model.hpp"

namespace dyncull {

namespace {

constexpr float kSteps = 65535.0f;

std::uint16_t quantise(float unit) {  // [0, 1] to the nearest of 65,536 steps
    // Non-negative, so adding a half and truncating rounds to nearest (lround is a call).
    // The clamp's comparisons also turn NaN into 0.
    const float clamped = unit > 0.0f ? std::min(unit, 1.0f) : 0.0f;
    return static_cast<std::uint16_t>(clamped * kSteps + 0.5f);
}

float signNotZero(float v) { return v < 0.0f ? -1.0f : 1.0f; }

void encodeNormal(const glm::vec3& n, std::uint16_t* out) {
    const float sum = std::abs(n.x) + std::abs(n.y) + std::abs(n.z);
    // A zero or non-finite normal (none from the file's checked leaves) encodes +Z.
    glm::vec2 p = sum > 0.0f && std::isfinite(sum) ? glm::vec2(n.x, n.y) / sum : glm::vec2(0.0f);
    if (sum > 0.0f && n.z < 0.0f) p = {(1.0f - std::abs(p.y)) * signNotZero(p.x), (1.0f - std::abs(p.x)) * signNotZero(p.y)};
    out[0] = quantise(p.x * 0.5f + 0.5f);
    out[1] = quantise(p.y * 0.5f + 0.5f);
}

glm::vec3 decodeNormal(const std::uint16_t* in) {
    glm::vec3 n(float(in[0]) / kSteps * 2.0f - 1.0f, float(in[1]) / kSteps * 2.0f - 1.0f, 0.0f);
    n.z = 1.0f - std::abs(n.x) - std::abs(n.y);
    const float fold = std::max(-n.z, 0.0f);
    n.x += n.x >= 0.0f ? -fold : fold;
    n.y += n.y >= 0.0f ? -fold : fold;
    return n / std::sqrt(n.x * n.x + n.y * n.y + n.z * n.z);  // never zero: |x| + |y| + |z| >= 1
}

std::size_t wordsFor(std::uint64_t vertices, std::uint64_t triangles) {
    const bool wide = vertices > 0x10000;
    return static_cast<std::size_t>(vertices * 5 + triangles * 3 * (wide ? 2 : 1));
}

}  // namespace

std::size_t compactLeafBytes(const StreamedLeaf& leaf) {
    return wordsFor(leaf.vertexCount, leaf.triangleCount) * sizeof(std::uint16_t);
}

void compactLeaf(const Mesh& mesh, const Aabb& box, CompactLeaf& out) {
    assert(mesh.normals.size() == mesh.positions.size());
    const auto v = static_cast<std::uint32_t>(mesh.positions.size());
    const auto t = static_cast<std::uint32_t>(mesh.indices.size() / 3);
    out.box = box;
    out.vertexCount = v;
    out.triangleCount = t;
    out.wideIndices = v > 0x10000;
    out.words.resize(wordsFor(v, t));
    const glm::vec3 extent = box.max - box.min;
    std::uint16_t* w = out.words.data();
    for (const glm::vec3& p : mesh.positions)
        for (int a = 0; a < 3; ++a) *w++ = extent[a] > 0.0f ? quantise((p[a] - box.min[a]) / extent[a]) : 0;
    for (const glm::vec3& n : mesh.normals) {
        encodeNormal(n, w);
        w += 2;
    }
    for (std::uint32_t i : mesh.indices) {
        *w++ = static_cast<std::uint16_t>(i);
        if (out.wideIndices) *w++ = static_cast<std::uint16_t>(i >> 16);
    }
}

void expandLeaf(const CompactLeaf& leaf, Mesh& out) {
    const std::uint32_t v = leaf.vertexCount;
    out.positions.resize(v);
    out.normals.resize(v);
    out.indices.resize(std::size_t{leaf.triangleCount} * 3);
    const glm::vec3 step = (leaf.box.max - leaf.box.min) / kSteps;
    const std::uint16_t* w = leaf.words.data();
    for (glm::vec3& p : out.positions) {
        // Clamped: min + q * step can round past max by an ulp.
        p = glm::clamp(leaf.box.min + glm::vec3(float(w[0]), float(w[1]), float(w[2])) * step, leaf.box.min, leaf.box.max);
        w += 3;
    }
    for (glm::vec3& n : out.normals) {
        n = decodeNormal(w);
        w += 2;
    }
    for (std::uint32_t& i : out.indices) {
        i = *w++;
        if (leaf.wideIndices) i |= std::uint32_t{*w++} << 16;
    }
}

}  // namespace dyncull
