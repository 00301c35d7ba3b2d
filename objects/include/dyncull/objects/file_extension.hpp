// The one convention for telling file kinds apart: the extension, compared in lowercase
// ("Bunny.PLY" is a PLY file). Every loader, scene reader and command that picks a reader
// or checks an output name by its extension goes through it.
#pragma once

#include <cctype>
#include <filesystem>
#include <string>

namespace dyncull {

/// `path`'s extension with its dot, in ASCII lowercase ("" if it has none).
inline std::string lowercaseExtension(const std::filesystem::path& path) {
    std::string ext = path.extension().string();
    for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    return ext;
}

}  // namespace dyncull
