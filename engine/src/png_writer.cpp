// PNG output through stb_image_write. STB_IMAGE_WRITE_STATIC keeps the implementation
// private to this file, so it cannot clash with the copy tinygltf links against.
#define STB_IMAGE_WRITE_IMPLEMENTATION
#define STB_IMAGE_WRITE_STATIC
#if defined(__GNUC__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmissing-field-initializers"
#pragma GCC diagnostic ignored "-Wshadow"
#pragma GCC diagnostic ignored "-Wunused-function"
#endif
#include <stb/stb_image_write.h>
#if defined(__GNUC__)
#pragma GCC diagnostic pop
#endif

#include "dyncull/engine/image.hpp"

namespace dyncull {

Status writePng(const Image& image, const std::filesystem::path& path) {
    if (image.width <= 0 || image.height <= 0 ||
        image.rgba.size() != static_cast<std::size_t>(image.width) * static_cast<std::size_t>(image.height) * 4)
        return Error{path.string() + ": image is empty or its pixel buffer does not match " +
                     std::to_string(image.width) + "x" + std::to_string(image.height)};
    if (!stbi_write_png(path.c_str(), image.width, image.height, 4, image.rgba.data(), image.width * 4))
        return Error{path.string() + ": cannot write PNG (directory missing or not writable?)"};
    return {};
}

}  // namespace dyncull
