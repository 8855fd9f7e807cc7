// libFuzzer harness: surfaces through tethash's assimp bridge (io::read_surface). The extension
// follows the content (ply, OFF, solid, OBJ vertex lines, else binary STL), so that plain files seed it. A surface
// read is then built into a BSP tree (an obstacle): built, or refused with Error, never a crash.
#include "fuzz_support.hpp"

#include "tethash/bsp.hpp"
#include "tethash/io/surface.hpp"

#include <string_view>

namespace {
const char* extension_for(std::string_view text)
{
    if (text.substr(0, 3) == "ply") return ".ply";
    if (text.substr(0, 3) == "OFF") return ".off";
    if (text.substr(0, 5) == "solid") return ".stl";
    if (text.substr(0, 2) == "v " || text.find("\nv ") != text.npos || text.substr(0, 1) == "#") return ".obj";
    return ".stl"; // binary STL: any 80-byte header
}
} // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size)
{
    const std::string_view text(reinterpret_cast<const char*>(data), size);
    const std::string path = tethash::fuzz::write_input(std::string("input") + extension_for(text), data, size);
    try {
        const tethash::io::SurfaceMesh s = tethash::io::read_surface(path);
        const auto n = s.vertices.rows();
        for (Eigen::Index t = 0; t < s.triangles.rows(); ++t)
            for (int k = 0; k < 3; ++k)
                if (s.triangles(t, k) < 0 || s.triangles(t, k) >= n) {
                    std::fprintf(stderr, "fuzz: triangle %ld refers to vertex %d of %ld\n", static_cast<long>(t),
                                 s.triangles(t, k), static_cast<long>(n));
                    std::abort();
                }
        const tethash::Bsp bsp(s.vertices, s.triangles, path);
        const Eigen::Vector3d centre = 0.5 * (bsp.box_lo() + bsp.box_hi());
        if (bsp.query(centre).inside && !(bsp.query(centre).depth >= 0)) std::abort();
    } catch (const tethash::Error&) {
    }
    return 0;
}
