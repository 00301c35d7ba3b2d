// loadScene: picks the loader from the file extension.
#include <cctype>
#include <string>

#include "dyncull/loaders/loaders.hpp"
#include "loader_common.hpp"

namespace dyncull {

Expected<Scene> loadScene(const std::filesystem::path& path) {
    std::string ext = path.extension().string();
    for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    if (ext == ".ply") return loadPly(path);
    if (ext == ".obj") return loadObj(path);
    if (ext == ".gltf" || ext == ".glb") return loadGltf(path);
    return detail::fileError(path, ext.empty() ? "no file extension; expected .ply, .obj, .gltf or .glb"
                                               : "unknown format '" + ext + "'; expected .ply, .obj, .gltf or .glb");
}

}  // namespace dyncull
