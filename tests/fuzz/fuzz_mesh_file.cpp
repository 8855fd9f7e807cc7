// libFuzzer harness for the single-file tet mesh readers through io::read_mesh: built once per format,
// TETHASH_FUZZ_EXTENSION (".vtk", ".vtu", ".msh", ".mesh", ".veg") picks the reader. For .vtu also
// io::read_vtu_contents (the triangles and data arrays that pictures of runs read).
#include "fuzz_support.hpp"

#include "tethash/io/mesh_io.hpp"
#include "tethash/io/vtu.hpp"

#include <cstdio>
#include <cstdlib>
#include <string_view>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size)
{
    const std::string path = tethash::fuzz::write_input("input" TETHASH_FUZZ_EXTENSION, data, size);
    try {
        tethash::io::ReadNotes notes;
        tethash::fuzz::expect_consistent(tethash::io::read_mesh(path, &notes));
    } catch (const tethash::Error&) {
    }
    if (std::string_view(TETHASH_FUZZ_EXTENSION) == ".vtu") {
        try {
            const tethash::io::VtuContents c = tethash::io::read_vtu_contents(path);
            tethash::fuzz::expect_consistent(c.mesh);
            const auto n = c.mesh.positions.rows();
            bool ok = c.triangle_cells.size() == static_cast<std::size_t>(c.triangles.rows()) &&
                      c.tet_cells.size() == static_cast<std::size_t>(c.mesh.tets.rows());
            for (Eigen::Index i = 0; i < c.triangles.size(); ++i)
                ok = ok && c.triangles.data()[i] >= 0 && c.triangles.data()[i] < n;
            for (const tethash::io::Field& f : c.fields.point)
                ok = ok && f.values.size() == static_cast<std::size_t>(n) * static_cast<std::size_t>(f.components);
            if (!ok) {
                std::fprintf(stderr, "fuzz: read_vtu_contents returned triangles or arrays out of range\n");
                std::abort();
            }
        } catch (const tethash::Error&) {
        }
    }
    return 0;
}
