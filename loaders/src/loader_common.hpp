// Private helpers shared by the file loaders (not installed): whole-file reading,
// error messages prefixed with the path, overflow-checked arithmetic on sizes read from
// files, and the final per-mesh normal/validation pass.
#pragma once

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <string>
#include <system_error>
#include <type_traits>

#include "checked_math.hpp"
#include "dyncull/objects/error.hpp"
#include "dyncull/objects/mesh.hpp"

namespace dyncull::detail {

inline Error fileError(const std::filesystem::path& path, const std::string& what) {
    std::string msg = path.string() + ": " + what;
    // Messages are one line even when a library reports several.
    for (char& c : msg)
        if (c == '\n' || c == '\r') c = ' ';
    while (!msg.empty() && msg.back() == ' ') msg.pop_back();
    return Error{std::move(msg), ErrorCode::BadFile};
}

/// Checks that `path` names a non-empty regular file (the common failures every loader
/// reports the same way).
inline Status checkFile(const std::filesystem::path& path) {
    std::error_code ec;
    const auto st = std::filesystem::status(path, ec);
    if (ec || !std::filesystem::exists(st)) return fileError(path, "file not found");
    if (!std::filesystem::is_regular_file(st)) return fileError(path, "not a regular file");
    const auto size = std::filesystem::file_size(path, ec);
    if (ec) return fileError(path, "cannot read file size: " + ec.message());
    if (size == 0) return fileError(path, "file is empty");
    return {};
}

/// Reads the whole file in one go (parsers then work on memory, which is what makes the
/// 3 MB ASCII bunny load in tens of milliseconds).
inline Status readWholeFile(const std::filesystem::path& path, std::string& out) {
    if (Status s = checkFile(path); !s) return s;
    std::FILE* f = std::fopen(path.c_str(), "rb");
    if (!f) return fileError(path, "cannot open file");
    std::error_code ec;
    const auto size = std::filesystem::file_size(path, ec);
    out.resize(static_cast<std::size_t>(size));
    const std::size_t got = std::fread(out.data(), 1, out.size(), f);
    std::fclose(f);
    if (got != out.size()) return fileError(path, "read error");
    return {};
}

/// Uses the file's normals if every one is finite and non-zero (normalising them), else
/// recomputes all of them; then checks the loader invariants. Returns "" or a problem.
inline std::string finishMesh(Mesh& mesh) {
    bool fileNormalsOk = !mesh.normals.empty() && mesh.normals.size() == mesh.positions.size();
    if (fileNormalsOk) {
        for (glm::vec3& n : mesh.normals) {
            const float len = std::sqrt(n.x * n.x + n.y * n.y + n.z * n.z);
            // Zero or non-finite normals cannot be normalised: fall back to computed ones.
            if (!(len > 0.0f) || !std::isfinite(len)) {
                fileNormalsOk = false;
                break;
            }
            n /= len;
        }
    }
    if (!fileNormalsOk) {
        // Validate first: computeNormals indexes positions without bounds checks.
        mesh.normals.clear();
        if (std::string problem = validateMesh(mesh); !problem.empty()) return problem;
        computeNormals(mesh);
    }
    return validateMesh(mesh);
}

}  // namespace dyncull::detail
