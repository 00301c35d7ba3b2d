// PNG output of read-back frames (screenshots, bench pictures).
#pragma once

#include <filesystem>

#include "dyncull/engine/image.hpp"
#include "dyncull/objects/error.hpp"

namespace dyncull {

/// Writes `image` as PNG. The parent directory must exist. Errors name the path; the file is
/// checked on write and close.
Status writePng(const Image& image, const std::filesystem::path& path);

}  // namespace dyncull
