// Wavefront OBJ loading through tinyobjloader; we do the fan triangulation, per-shape
// vertex deduplication and all range/finiteness checks ourselves.
#include <cmath>
#include <cstdint>
#include <exception>
#include <string>
#include <unordered_map>

#include <tiny_obj_loader.h>

#include "dyncull/objects/loaders.hpp"
#include "loader_common.hpp"

namespace dyncull {
namespace {

Expected<Scene> loadObjImpl(const std::filesystem::path& path) {
    if (Status s = detail::checkFile(path); !s) return Error{s.message()};
    tinyobj::ObjReaderConfig config;
    config.triangulate = false;  // we fan-triangulate, as for PLY
    config.vertex_color = false;
    config.mtl_search_path = path.parent_path().string();
    tinyobj::ObjReader reader;
    if (!reader.ParseFromFile(path.string(), config)) {
        std::string why = reader.Error();
        if (why.empty()) why = "parse error";
        return detail::fileError(path, why);
    }
    // Warnings (e.g. a missing .mtl) do not matter: materials are not used.

    const tinyobj::attrib_t& attrib = reader.GetAttrib();
    const std::size_t vertexCount = attrib.vertices.size() / 3;
    const std::size_t normalCount = attrib.normals.size() / 3;
    for (std::size_t i = 0; i < vertexCount; ++i)
        for (int k = 0; k < 3; ++k)
            if (!std::isfinite(attrib.vertices[3 * i + static_cast<std::size_t>(k)]))
                return detail::fileError(path, "vertex " + std::to_string(i + 1) + " has a non-finite coordinate");

    Scene scene;
    std::unordered_map<std::uint64_t, std::uint32_t> remap;  // (position, normal) index pair -> mesh vertex
    for (const tinyobj::shape_t& shape : reader.GetShapes()) {
        const tinyobj::mesh_t& src = shape.mesh;
        if (src.num_face_vertices.empty()) continue;  // lines/points only
        Mesh mesh;
        mesh.name = shape.name;
        remap.clear();
        bool allNormals = true;
        std::vector<std::uint32_t> face;
        std::size_t offset = 0;
        for (std::size_t f = 0; f < src.num_face_vertices.size(); ++f) {
            const std::size_t n = src.num_face_vertices[f];
            if (offset + n > src.indices.size()) return detail::fileError(path, "shape '" + shape.name + "': face list inconsistent");
            face.clear();
            for (std::size_t k = 0; k < n; ++k) {
                const tinyobj::index_t& ix = src.indices[offset + k];
                if (ix.vertex_index < 0 || static_cast<std::size_t>(ix.vertex_index) >= vertexCount)
                    return detail::fileError(path, "shape '" + shape.name + "': face " + std::to_string(f + 1) +
                                                       ": vertex index " + std::to_string(ix.vertex_index + 1) +
                                                       " out of range (" + std::to_string(vertexCount) + " vertices)");
                int nIdx = ix.normal_index;
                if (nIdx >= 0 && static_cast<std::size_t>(nIdx) >= normalCount)
                    return detail::fileError(path, "shape '" + shape.name + "': face " + std::to_string(f + 1) +
                                                       ": normal index " + std::to_string(nIdx + 1) + " out of range (" +
                                                       std::to_string(normalCount) + " normals)");
                if (nIdx < 0) allNormals = false;
                const std::uint64_t key = (static_cast<std::uint64_t>(static_cast<std::uint32_t>(ix.vertex_index)) << 32) |
                                          static_cast<std::uint32_t>(nIdx);
                auto [it, inserted] = remap.try_emplace(key, static_cast<std::uint32_t>(mesh.positions.size()));
                if (inserted) {
                    const std::size_t v = static_cast<std::size_t>(ix.vertex_index);
                    mesh.positions.emplace_back(attrib.vertices[3 * v], attrib.vertices[3 * v + 1], attrib.vertices[3 * v + 2]);
                    if (nIdx >= 0) {
                        const std::size_t q = static_cast<std::size_t>(nIdx);
                        mesh.normals.emplace_back(attrib.normals[3 * q], attrib.normals[3 * q + 1], attrib.normals[3 * q + 2]);
                    } else {
                        mesh.normals.emplace_back(0.0f);
                    }
                }
                face.push_back(it->second);
            }
            offset += n;
            // Fan triangulation; faces with fewer than 3 corners are dropped.
            for (std::size_t k = 1; k + 1 < face.size(); ++k) {
                mesh.indices.push_back(face[0]);
                mesh.indices.push_back(face[k]);
                mesh.indices.push_back(face[k + 1]);
            }
        }
        if (mesh.indices.empty()) continue;
        if (!allNormals) mesh.normals.clear();
        if (std::string problem = detail::finishMesh(mesh); !problem.empty())
            return detail::fileError(path, "shape '" + shape.name + "': " + problem);
        const auto index = static_cast<std::uint32_t>(scene.meshes.size());
        scene.instances.push_back(Instance{index, glm::mat4(1.0f), mesh.name});
        scene.meshes.push_back(std::move(mesh));
    }
    if (scene.meshes.empty()) return detail::fileError(path, "no faces (nothing to draw)");
    return scene;
}

}  // namespace

Expected<Scene> loadObj(const std::filesystem::path& path) {
    try {
        return loadObjImpl(path);
    } catch (const std::exception& e) {
        return detail::fileError(path, std::string("cannot load: ") + e.what());
    }
}

}  // namespace dyncull
