// libFuzzer harness for the single-file tet mesh readers through io::read_mesh: built once per format,
// TETHASH_FUZZ_EXTENSION (".vtk", ".vtu", ".msh", ".mesh", ".veg") picks the reader.
#include "fuzz_support.hpp"

#include "tethash/io/mesh_io.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size)
{
    const std::string path = tethash::fuzz::write_input("input" TETHASH_FUZZ_EXTENSION, data, size);
    try {
        tethash::io::ReadNotes notes;
        tethash::fuzz::expect_consistent(tethash::io::read_mesh(path, &notes));
    } catch (const tethash::Error&) {
    }
    return 0;
}
