// Animated GIF (GIF89a): a fixed palette with ordered dithering, and a variable-length LZW encoder (codes of 9 to
// 12 bits, a clear code when the table is full), written as the format's 255-byte sub-blocks.
#include "tethash/render/image_io.hpp"

#include <algorithm>

namespace tethash::render {
namespace {

constexpr int levels_r = 6, levels_g = 7, levels_b = 6; // 252 colours; indices 252..255 are greys
constexpr int bayer[4][4] = {{0, 8, 2, 10}, {12, 4, 14, 6}, {3, 11, 1, 9}, {15, 7, 13, 5}};

void put16(std::string& s, int v)
{
    s += static_cast<char>(v & 0xff);
    s += static_cast<char>((v >> 8) & 0xff);
}

/// Codes packed least significant bit first, cut into sub-blocks of at most 255 bytes.
class BitWriter {
  public:
    explicit BitWriter(std::string& out) : m_out(out) {}
    void put(unsigned code, int bits)
    {
        m_acc |= static_cast<std::uint64_t>(code) << m_bits;
        m_bits += bits;
        while (m_bits >= 8) {
            byte(static_cast<char>(m_acc & 0xff));
            m_acc >>= 8;
            m_bits -= 8;
        }
    }
    void finish()
    {
        if (m_bits > 0) byte(static_cast<char>(m_acc & 0xff));
        flush();
        m_out += '\0'; // block terminator
    }

  private:
    void byte(char c)
    {
        m_block += c;
        if (m_block.size() == 255) flush();
    }
    void flush()
    {
        if (m_block.empty()) return;
        m_out += static_cast<char>(m_block.size());
        m_out += m_block;
        m_block.clear();
    }
    std::string& m_out;
    std::string m_block;
    std::uint64_t m_acc = 0;
    int m_bits = 0;
};

} // namespace

GifEncoder::GifEncoder(int width, int height) : m_width(width), m_height(height)
{
    if (width < 1 || height < 1 || width > 65535 || height > 65535)
        throw Error("GIF size " + std::to_string(width) + "x" + std::to_string(height) + ": each side 1 to 65535");
    m_code.assign(4096 * 256, 0);
    m_stamp.assign(4096 * 256, 0);
}

void GifEncoder::add_frame(const Image& image, int delay_cs)
{
    if (image.width != m_width || image.height != m_height)
        throw Error("GIF frame of " + std::to_string(image.width) + "x" + std::to_string(image.height) +
                    " in an animation of " + std::to_string(m_width) + "x" + std::to_string(m_height));
    // Graphic control extension: leave the frame in place, the delay.
    m_data += "\x21\xf9\x04\x04";
    put16(m_data, std::clamp(delay_cs, 2, 65535));
    m_data += std::string("\0\0", 2);
    // Image descriptor: the whole screen, no local colour table.
    m_data += '\x2c';
    put16(m_data, 0);
    put16(m_data, 0);
    put16(m_data, m_width);
    put16(m_data, m_height);
    m_data += '\0';

    const auto index_at = [&](int x, int y) {
        const std::size_t i =
            3 * (static_cast<std::size_t>(y) * static_cast<std::size_t>(m_width) + static_cast<std::size_t>(x));
        const double d = (bayer[y & 3][x & 3] + 0.5) / 16;
        const auto level = [d](int v, int n) { return std::min(n - 1, static_cast<int>(v * (n - 1) / 255.0 + d)); };
        return static_cast<unsigned>((level(image.rgb[i], levels_r) * levels_g + level(image.rgb[i + 1], levels_g)) *
                                         levels_b +
                                     level(image.rgb[i + 2], levels_b));
    };

    constexpr int min_code_size = 8;
    constexpr unsigned clear = 1u << min_code_size, end = clear + 1;
    m_data += static_cast<char>(min_code_size);
    BitWriter bits(m_data);
    int code_size = min_code_size + 1;
    unsigned last = end; // the last code assigned
    const auto reset = [&] {
        if (++m_generation == 0) { // the stamps wrapped: forget every entry
            std::fill(m_stamp.begin(), m_stamp.end(), 0);
            m_generation = 1;
        }
        code_size = min_code_size + 1;
        last = end;
    };
    reset();
    bits.put(clear, code_size);
    unsigned prefix = index_at(0, 0);
    for (int y = 0; y < m_height; ++y)
        for (int x = y == 0 ? 1 : 0; x < m_width; ++x) {
            const unsigned c = index_at(x, y);
            const std::size_t key = static_cast<std::size_t>(prefix) * 256 + c;
            if (m_stamp[key] == m_generation) {
                prefix = m_code[key];
                continue;
            }
            bits.put(prefix, code_size);
            ++last;
            m_code[key] = static_cast<std::uint16_t>(last);
            m_stamp[key] = m_generation;
            if (last >= (1u << code_size)) ++code_size;
            if (last == 4095) {
                bits.put(clear, code_size);
                reset();
            }
            prefix = c;
        }
    bits.put(prefix, code_size);
    bits.put(end, code_size);
    bits.finish();
    ++m_frames;
}

std::string GifEncoder::finish() const
{
    std::string out = "GIF89a";
    put16(out, m_width);
    put16(out, m_height);
    out += '\xf7'; // a global colour table of 256 entries, 8 bits per primary
    out += std::string("\0\0", 2);
    for (int r = 0; r < levels_r; ++r)
        for (int g = 0; g < levels_g; ++g)
            for (int b = 0; b < levels_b; ++b) {
                out += static_cast<char>(r * 255 / (levels_r - 1));
                out += static_cast<char>(g * 255 / (levels_g - 1));
                out += static_cast<char>(b * 255 / (levels_b - 1));
            }
    for (int k = 0; k < 256 - levels_r * levels_g * levels_b; ++k)
        out += std::string(3, static_cast<char>(64 + 42 * k));
    // Loop forever (the NETSCAPE2.0 application extension).
    out += "\x21\xff\x0bNETSCAPE2.0\x03\x01";
    put16(out, 0);
    out += '\0';
    out += m_data;
    out += '\x3b';
    return out;
}

} // namespace tethash::render
