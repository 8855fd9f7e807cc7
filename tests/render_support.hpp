#pragma once
// Small scenes for the picture tests: cubes of six tets, written as frames, and the readers of the pictures' files
// (GIF blocks and LZW data, PNG through stb_image).
#include "tethash/io/vtu.hpp"
#include "tethash/render/raster.hpp"

#include <Eigen/Core>

#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#define STB_IMAGE_IMPLEMENTATION
#define STB_IMAGE_STATIC
#if defined(__GNUC__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wunused-function"
#endif
#include <stb/stb_image.h>
#if defined(__GNUC__)
#pragma GCC diagnostic pop
#endif

namespace tethash::test {

/// A cube of side `size` centred at `centre`: 8 vertices, the 6 tets around its diagonal.
inline TetMesh cube_mesh(const Eigen::Vector3d& centre, double size, Index object = 0)
{
    TetMesh m;
    m.positions.resize(8, 3);
    for (int v = 0; v < 8; ++v)
        m.positions.row(v) =
            (centre + size * Eigen::Vector3d((v & 1) - 0.5, ((v >> 1) & 1) - 0.5, ((v >> 2) & 1) - 0.5)).transpose();
    m.tets.resize(6, 4);
    m.tets << 0, 1, 3, 7, 0, 1, 5, 7, 0, 2, 3, 7, 0, 2, 6, 7, 0, 4, 5, 7, 0, 4, 6, 7;
    m.vertex_object.assign(8, object);
    m.tet_object.assign(6, object);
    return m;
}

/// The centroid of the mesh's vertices.
inline Eigen::Vector3d centroid(const TetMesh& m)
{
    return m.positions.colwise().mean().transpose();
}

/// True when `c` is `base` shaded: each channel base × s for one s in [0.3, 1] (rounding allowed).
inline bool is_shade_of(render::Rgb c, render::Rgb base)
{
    const double s = (c.r + c.g + c.b) / static_cast<double>(base.r + base.g + base.b);
    if (s < 0.3 || s > 1.01) return false;
    return std::abs(c.r - s * base.r) <= 2.5 && std::abs(c.g - s * base.g) <= 2.5 && std::abs(c.b - s * base.b) <= 2.5;
}

/// The structure of a GIF file: its size, the colour table, and each image's colour indices (LZW decoded).
struct GifFile {
    bool valid = false;
    std::string error;
    int width = 0, height = 0;
    std::vector<render::Rgb> palette;
    std::vector<std::vector<int>> images; ///< one index per pixel
    std::vector<int> delays;              ///< hundredths of a second, per image
};

inline GifFile parse_gif(const std::string& d)
{
    GifFile g;
    std::size_t p = 0;
    const auto u8 = [&](std::size_t i) { return i < d.size() ? static_cast<unsigned char>(d[i]) : 0u; };
    const auto u16 = [&](std::size_t i) { return static_cast<int>(u8(i) | (u8(i + 1) << 8)); };
    const auto fail = [&](const std::string& why) {
        g.error = why + " at byte " + std::to_string(p);
        return g;
    };
    if (d.size() < 13 || d.compare(0, 6, "GIF89a") != 0) return fail("no GIF89a header");
    g.width = u16(6), g.height = u16(8);
    const unsigned flags = u8(10);
    p = 13;
    if (flags & 0x80) {
        const int n = 2 << (flags & 7);
        for (int k = 0; k < n; ++k, p += 3)
            g.palette.push_back({static_cast<std::uint8_t>(u8(p)), static_cast<std::uint8_t>(u8(p + 1)),
                                 static_cast<std::uint8_t>(u8(p + 2))});
    }
    const auto sub_blocks = [&](std::string* into) {
        while (p < d.size()) {
            const unsigned n = u8(p++);
            if (n == 0) return true;
            if (into) into->append(d, p, n);
            p += n;
        }
        return false;
    };
    int delay = 0;
    while (p < d.size()) {
        const unsigned b = u8(p++);
        if (b == 0x3b) {
            g.valid = p == d.size();
            if (!g.valid) return fail("bytes after the trailer");
            return g;
        }
        if (b == 0x21) {
            const unsigned label = u8(p++);
            if (label == 0xf9) delay = u16(p + 2); // size byte, packed fields, delay
            if (!sub_blocks(nullptr)) return fail("unterminated extension");
        } else if (b == 0x2c) {
            const int x = u16(p), y = u16(p + 2), w = u16(p + 4), h = u16(p + 6);
            const unsigned f = u8(p + 8);
            p += 9;
            if (x != 0 || y != 0 || w != g.width || h != g.height || (f & 0x80)) return fail("unexpected descriptor");
            const int min_size = static_cast<int>(u8(p++));
            std::string data;
            if (!sub_blocks(&data)) return fail("unterminated image data");
            // LZW decoding.
            const int clear = 1 << min_size, end = clear + 1;
            std::vector<std::vector<int>> table;
            const auto reset = [&] {
                table.assign(static_cast<std::size_t>(end + 1), {});
                for (int k = 0; k < clear; ++k)
                    table[static_cast<std::size_t>(k)] = {k};
            };
            reset();
            int size = min_size + 1;
            std::size_t bit = 0;
            std::vector<int> out, prev;
            bool ended = false;
            while (bit + static_cast<std::size_t>(size) <= 8 * data.size()) {
                int code = 0;
                for (int k = 0; k < size; ++k, ++bit)
                    code |= ((static_cast<unsigned char>(data[bit / 8]) >> (bit % 8)) & 1) << k;
                if (code == clear) {
                    reset();
                    size = min_size + 1;
                    prev.clear();
                    continue;
                }
                if (code == end) {
                    ended = true;
                    break;
                }
                std::vector<int> entry;
                if (code < static_cast<int>(table.size()) && !table[static_cast<std::size_t>(code)].empty())
                    entry = table[static_cast<std::size_t>(code)];
                else if (code == static_cast<int>(table.size()) && !prev.empty())
                    entry = prev, entry.push_back(prev[0]);
                else
                    return fail("bad LZW code " + std::to_string(code));
                out.insert(out.end(), entry.begin(), entry.end());
                if (!prev.empty() && table.size() < 4096) {
                    prev.push_back(entry[0]);
                    table.push_back(prev);
                    if (table.size() == (1u << size) && size < 12) ++size;
                }
                prev = entry;
            }
            if (!ended) return fail("image data without an end code");
            if (out.size() != static_cast<std::size_t>(w) * static_cast<std::size_t>(h))
                return fail("image of " + std::to_string(out.size()) + " pixels");
            g.images.push_back(out);
            g.delays.push_back(delay);
        } else {
            return fail("unknown block " + std::to_string(b));
        }
    }
    return fail("no trailer");
}

/// A PNG file's pixels (stb_image's decoder, a reader of its own): `ok` false when it does not decode.
struct Png {
    bool ok = false;
    int width = 0, height = 0;
    std::vector<std::uint8_t> rgb; ///< 3 bytes a pixel, rows from the top
};

inline Png decode_png(const std::string& bytes)
{
    Png r;
    int n = 0;
    unsigned char* px = stbi_load_from_memory(reinterpret_cast<const unsigned char*>(bytes.data()),
                                              static_cast<int>(bytes.size()), &r.width, &r.height, &n, 3);
    if (!px) return r;
    r.ok = true;
    r.rgb.assign(px, px + 3 * static_cast<std::size_t>(r.width) * static_cast<std::size_t>(r.height));
    stbi_image_free(px);
    return r;
}

} // namespace tethash::test
