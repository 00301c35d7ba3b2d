// loadPly: a PLY file into one in-memory mesh, collected from the streaming parser
// (ply_reader.cpp). Polygons are ear-clipped here, where every position is at hand.
#include <exception>
#include <optional>
#include <string>
#include <vector>

#include "dyncull/loaders/loaders.hpp"
#include "dyncull/loaders/ply_stream.hpp"
#include "loader_common.hpp"
#include "dyncull/objects/polygon_triangulation.hpp"

namespace dyncull {
namespace {

// Arrays grow only as values arrive (never sized from header counts), so memory stays
// proportional to the data actually present in the file.
class MeshCollector final : public MeshStreamSink {
public:
    std::vector<glm::vec3> positions, normals;
    std::vector<std::uint32_t> indices;

    Status begin(const MeshStreamLayout& layout) override {
        layout_ = layout;
        return {};
    }
    Status vertex(const glm::vec3& position, const glm::vec3& normal) override {
        positions.push_back(position);
        if (layout_.normals) normals.push_back(normal);
        return {};
    }
    Status face(std::span<const std::uint32_t> corners) override {
        // Faces read before the vertex element is complete wait (corners, then sizes)
        // until their positions are known, since triangulation needs them.
        if (positions.size() < layout_.vertices) {
            deferredCorners_.insert(deferredCorners_.end(), corners.begin(), corners.end());
            deferredSizes_.push_back(static_cast<std::uint32_t>(corners.size()));
            return {};
        }
        return triangulate(corners);
    }
    /// Triangulates the faces that came before the vertex element.
    Status finish() {
        std::size_t at = 0;
        for (std::uint32_t n : deferredSizes_) {
            if (Status s = triangulate({deferredCorners_.data() + at, n}); !s) return s;
            at += n;
        }
        return {};
    }

private:
    Status triangulate(std::span<const std::uint32_t> idx) {
        if (idx.size() == 3) {  // the common case needs no geometry
            indices.insert(indices.end(), idx.begin(), idx.end());
            return {};
        }
        corners_.clear();
        for (std::uint32_t i : idx) corners_.push_back(positions[i]);
        local_.clear();
        // Zero-area polygons give no triangles; self-intersecting ones give best-effort triangles.
        if (triangulatePolygon(corners_, local_, scratch_) == Triangulation::TooComplex)
            return Error{"face with " + std::to_string(idx.size()) + " corners is too complex to triangulate"};
        for (std::uint32_t k : local_) indices.push_back(idx[k]);
        return {};
    }

    MeshStreamLayout layout_;
    std::vector<std::uint32_t> deferredCorners_, deferredSizes_, local_;
    std::vector<glm::vec3> corners_;
    TriangulationScratch scratch_;
};

Expected<Scene> loadPlyImpl(const std::filesystem::path& path) {
    MeshCollector c;
    if (Status s = streamPly(path, c); !s) return s.error();
    if (Status s = c.finish(); !s) return detail::fileError(path, s.message());
    if (c.indices.empty())
        return detail::fileError(path, "no triangles (every face has fewer than 3 vertices or zero area)");

    Mesh mesh;
    mesh.name = path.stem().string();
    mesh.positions = std::move(c.positions);
    mesh.normals = std::move(c.normals);
    mesh.indices = std::move(c.indices);
    if (std::string problem = detail::finishMesh(mesh); !problem.empty()) return detail::fileError(path, problem);

    Scene scene;
    scene.meshes.push_back(std::move(mesh));
    scene.instances.push_back(Instance{0, glm::mat4(1.0f), scene.meshes[0].name});
    return scene;
}

}  // namespace

Expected<Scene> loadPly(const std::filesystem::path& path) {
    try {
        return loadPlyImpl(path);
    } catch (const std::exception& e) {  // e.g. std::bad_alloc on a huge but plausible file
        return detail::fileError(path, std::string("cannot load: ") + e.what());
    }
}

}  // namespace dyncull
