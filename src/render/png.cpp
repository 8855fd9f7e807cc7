// PNG through stb_image_write (Debian: libstb-dev), its implementation compiled here once.
#include "tethash/render/image_io.hpp"

#include "tethash/io/file.hpp"

#if defined(__GNUC__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmissing-field-initializers"
#pragma GCC diagnostic ignored "-Wsign-compare"
#endif
#define STB_IMAGE_WRITE_IMPLEMENTATION
#define STB_IMAGE_WRITE_STATIC
#define STBI_WRITE_NO_STDIO
#include <stb/stb_image_write.h>
#if defined(__GNUC__)
#pragma GCC diagnostic pop
#endif

namespace tethash::render {

std::string encode_png(const Image& image)
{
    if (image.width <= 0 || image.height <= 0 ||
        image.rgb.size() != 3 * static_cast<std::size_t>(image.width) * static_cast<std::size_t>(image.height))
        throw Error("encode_png: the image is empty or its pixels do not match its size");
    std::string out;
    const auto append = [](void* context, void* data, int size) {
        static_cast<std::string*>(context)->append(static_cast<const char*>(data), static_cast<std::size_t>(size));
    };
    if (!stbi_write_png_to_func(append, &out, image.width, image.height, 3, image.rgb.data(), 3 * image.width))
        throw Error("encode_png: the PNG encoder failed (out of memory?)");
    return out;
}

void write_png(const std::string& path, const Image& image)
{
    if (io::extension_of(path) != ".png") throw Error(path + ": expected a .png file name");
    io::write_text_file(path, encode_png(image));
}

} // namespace tethash::render
