// loadScene: picks the loader from the file extension.
#include <string>

#include "dyncull/loaders/loaders.hpp"
#include "dyncull/objects/file_extension.hpp"
#include "loader_common.hpp"

namespace dyncull {

Expected<Scene> loadScene(const std::filesystem::path& path) {
    const std::string ext = lowercaseExtension(path);
    if (ext == ".ply") return loadPly(path);
    if (ext == ".obj") return loadObj(path);
    if (ext == ".gltf" || ext == ".glb") return loadGltf(path);
    return detail::fileError(path, ext.empty() ? "no file extension; expected .ply, .obj, .gltf or .glb"
                                               : "unknown format '" + ext + "'; expected .ply, .obj, .gltf or .glb");
}

}  // namespace dyncull
