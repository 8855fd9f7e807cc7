// libFuzzer harness: the TetGen reader. The input is the .node file, a NUL byte, then the .ele file
// (no NUL: an empty .ele); the pair is read through either name.
#include "fuzz_support.hpp"

#include "tethash/io/mesh_io.hpp"

#include <algorithm>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size)
{
    const std::uint8_t* end = data + size;
    const std::uint8_t* nul = std::find(data, end, std::uint8_t(0));
    const std::string node = tethash::fuzz::write_input("input.node", data, static_cast<std::size_t>(nul - data));
    const std::uint8_t* ele = nul == end ? end : nul + 1;
    tethash::fuzz::write_input("input.ele", ele, static_cast<std::size_t>(end - ele));
    try {
        tethash::io::ReadNotes notes;
        tethash::fuzz::expect_consistent(tethash::io::read_mesh(node, &notes));
    } catch (const tethash::Error&) {
    }
    return 0;
}
