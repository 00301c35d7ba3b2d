// What every loader must guarantee for any input (objects/include/dyncull/loaders/loaders.hpp):
// either an Error with a one-line message naming the file, or a complete Scene whose meshes
// all pass validateMesh() and whose instances name existing meshes with finite matrices.
// A violation aborts, which libFuzzer reports as a crash with the input saved.
#pragma once

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>

#include "dyncull/bsp/local_bsp.hpp"
#include "dyncull/loaders/loaders.hpp"

namespace dyncull::fuzz {

[[noreturn]] inline void violation(const std::string& what) {
    std::fprintf(stderr, "loader contract violated: %s\n", what.c_str());
    std::abort();
}

inline void checkLoaderResult(const Expected<Scene>& r, const std::filesystem::path& path) {
    if (!r) {
        const std::string& m = r.error().message;
        if (m.empty() || m.find('\n') != std::string::npos) violation("error message empty or multi-line: " + m);
        if (m.find(path.filename().string()) == std::string::npos) violation("error message does not name the file: " + m);
        return;
    }
    for (const Mesh& mesh : r->meshes) {
        if (std::string why = validateMesh(mesh); !why.empty()) violation("returned mesh invalid: " + why);
        if (mesh.normals.size() != mesh.positions.size()) violation("returned mesh without one normal per vertex");
        for (const glm::vec3& n : mesh.normals)
            if (!std::isfinite(n.x) || !std::isfinite(n.y) || !std::isfinite(n.z)) violation("non-finite normal");
        // What a loaded mesh goes through next: its local BSP (kept to small meshes so an
        // iteration stays fast). Any input the loader accepts must build or fail cleanly.
        if (mesh.indices.size() / 3 <= 2048) {
            auto bsp = buildLocalBsp(mesh);
            if (bsp && bsp->nodes.empty()) violation("local BSP without nodes");
        }
    }
    for (const Instance& inst : r->instances) {
        if (inst.mesh >= r->meshes.size()) violation("instance names a missing mesh");
        for (int c = 0; c < 4; ++c)
            for (int k = 0; k < 4; ++k)
                if (!std::isfinite(inst.transform[c][k])) violation("instance matrix not finite");
    }
}

}  // namespace dyncull::fuzz
