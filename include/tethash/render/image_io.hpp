#pragma once
/// \file render/image_io.hpp
/// Pictures to bytes and files: PNG (stb_image_write), animated GIF (an LZW encoder of its own, a fixed palette
/// with ordered dithering). Files are written atomically (io/file.hpp): a failed write leaves nothing half-written.
#include "tethash/error.hpp"
#include "tethash/render/raster.hpp"

#include <cstdint>
#include <string>
#include <vector>

namespace tethash::render {

/// The PNG file of `image` (8-bit RGB).
std::string encode_png(const Image& image);

/// An animated GIF built frame by frame: 256 colours (6 × 7 × 6 levels of red, green, blue and 4 greys) with a
/// 4 × 4 ordered dither, looping forever.
class GifEncoder {
  public:
    /// Throws Error for a side outside 1..65535.
    GifEncoder(int width, int height);
    /// Appends a frame of the encoder's size, shown for `delay_cs` hundredths of a second (at least 2: browsers slow
    /// down shorter delays). Throws Error for an image of another size.
    void add_frame(const Image& image, int delay_cs);
    /// The file's bytes (header, frames, trailer); frames() frames.
    std::string finish() const;
    int frames() const { return m_frames; }

  private:
    int m_width, m_height, m_frames = 0;
    std::string m_data;                         ///< the frames so far
    std::vector<std::uint16_t> m_code, m_stamp; ///< LZW table (prefix × 256 + byte → code), valid where stamp matches
    std::uint16_t m_generation = 0;
};

/// `path` ending in .png: encode_png written atomically. Throws Error for another extension.
void write_png(const std::string& path, const Image& image);

} // namespace tethash::render
