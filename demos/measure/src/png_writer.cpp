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

#include <cstdlib>
#include <memory>
#include <string_view>

#include "dyncull/measure/png_writer.hpp"
#include "dyncull/objects/checked_write.hpp"

namespace dyncull {

Status writePng(const Image& image, const std::filesystem::path& path) {
    if (image.width <= 0 || image.height <= 0 ||
        image.rgba.size() != static_cast<std::size_t>(image.width) * static_cast<std::size_t>(image.height) * 4)
        return Error{path.string() + ": image is empty or its pixel buffer does not match " +
                     std::to_string(image.width) + "x" + std::to_string(image.height)};
    // Encode in memory, then write with every write and the close checked: stb's own file
    // path ignores fwrite and fclose failures, so a full disk would pass as written.
    int size = 0;
    std::unique_ptr<unsigned char, decltype(&std::free)> png(
        stbi_write_png_to_mem(image.rgba.data(), image.width * 4, image.width, image.height, 4, &size), &std::free);
    if (!png || size <= 0) return Error{path.string() + ": PNG encoding failed (out of memory?)"};
    return writeFileChecked(path, std::string_view(reinterpret_cast<const char*>(png.get()), static_cast<std::size_t>(size)));
}

}  // namespace dyncull
