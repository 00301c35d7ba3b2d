// Helpers for the demos tests: temp directories and content hashes of generated scenes.
#pragma once

#include <filesystem>
#include <string>

#include <gtest/gtest.h>

#include "prepared_scene.hpp"
#include "scene_cache.hpp"

namespace dyncull::test {

/// A fresh directory under the system temp dir, removed on destruction.
class TempDir {
public:
    TempDir() {
        const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
        path_ = std::filesystem::temp_directory_path() /
                ("dyncull_demos_" + std::string(info->test_suite_name()) + "_" + info->name());
        std::filesystem::remove_all(path_);
        std::filesystem::create_directories(path_);
    }
    ~TempDir() {
        std::error_code ec;
        std::filesystem::remove_all(path_, ec);
    }
    const std::filesystem::path& path() const { return path_; }

private:
    std::filesystem::path path_;
};

inline std::uint64_t hashMesh(const Mesh& m, std::uint64_t h = 0xcbf29ce484222325ull) {
    h = fnv1a64(m.name.data(), m.name.size(), h);
    h = fnv1a64(m.positions.data(), m.positions.size() * sizeof(glm::vec3), h);
    h = fnv1a64(m.normals.data(), m.normals.size() * sizeof(glm::vec3), h);
    return fnv1a64(m.indices.data(), m.indices.size() * sizeof(std::uint32_t), h);
}

inline std::uint64_t hashObjects(const std::vector<PlacedObject>& objects, std::uint64_t h) {
    for (const PlacedObject& o : objects) {
        h = fnv1a64(&o.model, sizeof o.model, h);
        h = fnv1a64(&o.transform.translation, sizeof(glm::vec3), h);
        h = fnv1a64(&o.transform.rotation, sizeof(glm::quat), h);
        h = fnv1a64(&o.transform.scale, sizeof(glm::vec3), h);
    }
    return h;
}

inline std::uint64_t hashScene(const GeneratedScene& s) {
    std::uint64_t h = 0xcbf29ce484222325ull;
    for (const Mesh& m : s.meshes) h = hashMesh(m, h);
    return hashObjects(s.objects, h);
}

inline std::uint64_t hashScene(const PreparedScene& s) {
    std::uint64_t h = 0xcbf29ce484222325ull;
    for (const LocalBsp& b : s.models) {
        h = hashMesh(b.mesh, h);
        h = fnv1a64(b.nodes.data(), b.nodes.size() * sizeof(LocalBspNode), h);
    }
    return hashObjects(s.objects, h);
}

}  // namespace dyncull::test
