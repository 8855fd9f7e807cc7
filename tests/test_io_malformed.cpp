// Malformed files that need several consistent large numbers, which a fuzzer rarely builds: each
// must fail fast with exit status 2 (or io Error through the API), naming the file and what is
// wrong, without first allocating what its header declares. The command-line cases run under a
// virtual-memory limit (not under AddressSanitizer, whose shadow memory needs terabytes of address space).
#include "support.hpp"

#include "tethash/error.hpp"
#include "tethash/io/mesh_io.hpp"

#include <gtest/gtest.h>

#include <chrono>
#include <cstdint>
#include <filesystem>
#include <string>

using namespace tethash;
using namespace tethash::test;
namespace fs = std::filesystem;

namespace {

#if defined(__SANITIZE_ADDRESS__)
constexpr bool kAsan = true;
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
constexpr bool kAsan = true;
#else
constexpr bool kAsan = false;
#endif
#else
constexpr bool kAsan = false;
#endif

/// Address space the command may use: far below what the crafted headers declare (gigabytes).
constexpr int kLimitKiB = 400 * 1024;

/// Runs tethash under `ulimit -v` (plain run under ASan) and checks the error contract: status 2,
/// one "tethash: error:" line holding every fragment, done in a few seconds.
void expect_bounded_error(const std::string& args, const std::vector<std::string>& fragments)
{
    const std::string limit = kAsan ? "" : "ulimit -v " + std::to_string(kLimitKiB) + "; ";
    const auto start = std::chrono::steady_clock::now();
    const RunResult r = run_shell(limit + quote(TETHASH_EXE) + " " + args);
    const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    EXPECT_EQ(r.status, 2) << args << "\n" << r.err;
    EXPECT_EQ(r.err.rfind("tethash: error: ", 0), 0u) << args << "\n" << r.err;
    for (const auto& f : fragments)
        EXPECT_NE(r.err.find(f), std::string::npos) << args << ": no '" << f << "' in\n" << r.err;
    EXPECT_LT(s, 10.0) << args;
}

std::string io_error(const fs::path& p)
{
    try {
        io::read_mesh(p.string());
    } catch (const Error& e) {
        return e.what();
    }
    return "";
}

template <class T> void put(std::string& s, T v)
{
    s.append(reinterpret_cast<const char*>(&v), sizeof(T)); // little-endian hosts only, like tethash
}

/// A .vtu whose points are one zlib block declared `declared` bytes long but holding an empty stream.
std::string vtu_with_zlib_block(std::uint64_t points)
{
    std::string s = R"(<?xml version="1.0"?>
<VTKFile type="UnstructuredGrid" version="1.0" byte_order="LittleEndian" header_type="UInt64" compressor="vtkZLibDataCompressor">
<UnstructuredGrid><Piece NumberOfPoints=")" +
                    std::to_string(points) + R"(" NumberOfCells="0">
<Points><DataArray type="Float64" NumberOfComponents="3" format="appended" offset="0"/></Points>
</Piece></UnstructuredGrid>
<AppendedData encoding="raw">_)";
    const std::string stream("\x78\x9c\x03\x00\x00\x00\x00\x01", 8); // zlib of zero bytes
    put<std::uint64_t>(s, 1);                                        // blocks
    put<std::uint64_t>(s, 3 * 8 * points);                           // block size
    put<std::uint64_t>(s, 0);                                        // last block: full
    put<std::uint64_t>(s, stream.size());
    s += stream;
    s += "\n</AppendedData></VTKFile>\n";
    return s;
}

const char* const kTetVtk = "# vtk DataFile Version 3.0\nt\nASCII\nDATASET UNSTRUCTURED_GRID\n"
                            "POINTS 4 double\n0 0 0 1 0 0 0 1 0 0 0 1\nCELLS 1 5\n4 0 1 2 3\nCELL_TYPES 1\n10\n";

} // namespace

TEST(IoMalformed, VtuZlibHeaderDeclaringGigabytesFailsBeforeAllocating)
{
    const auto dir = temp_dir();
    // 2^27 points × 3 × 8 bytes = 3 GiB declared, 8 compressed bytes present.
    const fs::path p = dir / "huge_block.vtu";
    write_text(p, vtu_with_zlib_block(std::uint64_t(1) << 27));
    EXPECT_LT(fs::file_size(p), 1000u);
    const std::string e = io_error(p);
    EXPECT_NE(e.find(p.string()), std::string::npos) << e;
    EXPECT_NE(e.find("cannot inflate to the 3221225472 bytes"), std::string::npos) << e;
    expect_bounded_error("info " + quote(p), {p.string(), "zlib block 0", "cannot inflate"});
}

TEST(IoMalformed, VtuZlibBlockThatInflatesShortIsCorrupt)
{
    const auto dir = temp_dir();
    // 40 declared bytes pass the ratio check, but the stream yields none.
    const fs::path p = dir / "short_block.vtu";
    write_text(p, vtu_with_zlib_block(1));
    const std::string e = io_error(p);
    EXPECT_NE(e.find("is corrupt or does not inflate to 24 bytes"), std::string::npos) << e;
}

TEST(IoMalformed, VtuNestedDeeplyIsRejectedNotACrash)
{
    const auto dir = temp_dir();
    const fs::path p = dir / "deep.vtu";
    std::string s = "<VTKFile type=\"UnstructuredGrid\">\n";
    for (int i = 0; i < 400000; ++i)
        s += "<a>";
    for (int i = 0; i < 400000; ++i)
        s += "</a>";
    s += "\n</VTKFile>\n";
    write_text(p, s);
    const std::string e = io_error(p);
    EXPECT_NE(e.find(p.string() + ":2: expected at most 256 nested elements"), std::string::npos) << e;
    expect_bounded_error("info " + quote(p), {p.string(), "nested elements"});
}

TEST(IoMalformed, GmshAsciiCountsThatOverflowAreRejected)
{
    const auto dir = temp_dir();
    const std::string head = "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Nodes\n1 1 1 1\n3 1 0 1\n1\n0 0 0\n$EndNodes\n";
    // 4.6e18 triangles: count × (1 + 3) overflows a signed 64-bit integer.
    const fs::path p = dir / "huge_count.msh";
    write_text(p, head + "$Elements\n1 4611686018427387903 1 4611686018427387903\n2 1 2 4611686018427387903\n"
                         "$EndElements\n");
    const std::string e = io_error(p);
    EXPECT_NE(e.find(p.string() + ":12: expected 4611686018427387903 elements"), std::string::npos) << e;
    expect_bounded_error("info " + quote(p), {p.string(), "4611686018427387903 elements", "too few to hold them"});

    // The same for nodes, and for a 2.2 element count.
    const fs::path q = dir / "huge_nodes.msh";
    write_text(q, "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Nodes\n1 2000000000 1 2000000000\n3 1 0 2000000000\n"
                  "1\n0 0 0\n$EndNodes\n");
    expect_bounded_error("info " + quote(q), {q.string(), "expected 2000000000 nodes"});
    const fs::path r = dir / "huge22.msh";
    write_text(r, "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n1\n1 0 0 0\n$EndNodes\n$Elements\n"
                  "4611686018427387903\n$EndElements\n");
    expect_bounded_error("info " + quote(r), {r.string(), "expected 4611686018427387903 elements"});
}

TEST(IoMalformed, HugeObjectIdsAreRejectedNotOverflowed)
{
    const auto dir = temp_dir();
    const fs::path p = dir / "big_object.vtk";
    write_text(p, std::string(kTetVtk) + "CELL_DATA 1\nSCALARS object int 1\nLOOKUP_TABLE default\n2147483647\n");
    const std::string e = io_error(p);
    EXPECT_NE(e.find("object id 2147483647"), std::string::npos) << e;
    expect_bounded_error("info " + quote(p), {p.string(), "object id 2147483647", "below the number of cells (1)"});

    const fs::path q = dir / "big_object.vtu";
    write_text(q, R"(<VTKFile type="UnstructuredGrid"><UnstructuredGrid><Piece NumberOfPoints="4" NumberOfCells="1">
<Points><DataArray type="Float64" NumberOfComponents="3" format="ascii">0 0 0 1 0 0 0 1 0 0 0 1</DataArray></Points>
<Cells><DataArray type="Int32" Name="connectivity" format="ascii">0 1 2 3</DataArray>
<DataArray type="Int32" Name="offsets" format="ascii">4</DataArray>
<DataArray type="UInt8" Name="types" format="ascii">10</DataArray></Cells>
<PointData><DataArray type="Int32" Name="object" format="ascii">0 0 0 2147483647</DataArray></PointData>
</Piece></UnstructuredGrid></VTKFile>
)");
    expect_bounded_error("info " + quote(q), {q.string(), "gives point 3 object id 2147483647"});

    // Ids below the count still number objects as before.
    const fs::path ok = dir / "two_objects.vtk";
    write_text(ok, std::string(kTetVtk) + "POINT_DATA 4\nSCALARS object int 1\nLOOKUP_TABLE default\n0 0 0 3\n");
    EXPECT_EQ(io::read_mesh(ok.string()).num_objects(), 4);
}

TEST(IoMalformed, LegacyBitPointsAreRejectedBeforeDecoding)
{
    const auto dir = temp_dir();
    // 11,184,810 points as bits: 4 MB of file, which decoded cost a double per bit (256 MB) and more.
    const std::size_t n = 11184810;
    std::string s =
        "# vtk DataFile Version 3.0\nbits\nBINARY\nDATASET UNSTRUCTURED_GRID\nPOINTS " + std::to_string(n) + " bit\n";
    s.append((3 * n + 7) / 8, '\x55');
    const fs::path p = dir / "bit_points.vtk";
    write_text(p, s);
    const std::string e = io_error(p);
    EXPECT_NE(e.find(p.string() + ": byte 81: expected the data type of POINTS to be a number type"), std::string::npos)
        << e;
    expect_bounded_error("info " + quote(p), {p.string(), "POINTS", "found bit"});
}

TEST(IoMalformed, SceneIntegersAreCheckedBeforeNarrowing)
{
    const auto dir = temp_dir();
    const std::string object = "[[object]]\ngenerate = { shape = \"box\", resolution = 2 }\n";
    const std::vector<std::pair<std::string, std::string>> cases = {
        {"steps = 4294967297\n" + object, "key 'steps': must be in [0, 2147483647], found 4294967297"},
        {object + "[[pin]]\nobject = 4294967297\nvertices = [0]\n",
         "key 'pin[0].object': must be in [0, 2147483647], found 4294967297"},
        {object + "[[pin]]\nobject = 0\nvertices = [4294967296]\n",
         "key 'pin[0].vertices': must be in [0, 2147483647], found 4294967296"},
        {"substeps = 2147483648\n" + object, "key 'substeps': must be in [1, 2147483647]"},
        {"iterations = -4294967295\n" + object, "key 'iterations': must be in [0, 2147483647]"},
        {"max_substeps = -1\n" + object, "key 'max_substeps': must be in [0, 2147483647]"},
        {"[output]\nevery = 4294967296\n" + object, "key 'output.every': must be in [0, 2147483647]"},
        {"[detector]\nthreads = 4294967297\n" + object, "key 'detector.threads': must be in [0, 2147483647]"},
        {"[[object]]\ngenerate = { shape = \"box\", resolution = 4294967297 }\n",
         "key 'object[0].generate.resolution': must be in [1, 1000]"},
        {"[[object]]\nmesh = \"x.obj\"\nsurface_resolution = 4294967297\n",
         "key 'object[0].surface_resolution': must be in [1, 1000]"},
    };
    int k = 0;
    for (const auto& [text, fragment] : cases) {
        const fs::path p = dir / (std::to_string(k++) + ".toml");
        write_text(p, text);
        expect_bounded_error("simulate " + quote(p) + " --out " + quote(dir / "out"), {p.string(), fragment});
    }
}

TEST(IoMalformed, SceneSyntaxErrorsAreCleanErrors)
{
    // toml++ asserts on these when built with its assertions on; Debian's build returns a parse error.
    const auto dir = temp_dir();
    int k = 0;
    for (const std::string text : {"[=", "a=[}", "\xc3\xa9 = 1\n"}) {
        const fs::path p = dir / (std::to_string(k++) + ".toml");
        write_text(p, text);
        expect_bounded_error("simulate " + quote(p) + " --out " + quote(dir / "out"), {p.string(), "TOML syntax"});
        EXPECT_FALSE(fs::exists(dir / "out"));
    }
}

TEST(IoMalformed, FuzzFindingsFailCleanly)
{
    // tests/data/fuzz: inputs on which a harness of tests/fuzz once crashed (docs/robustness.md).
    // Each must now give exit status 2 and a message naming the file.
    const auto dir = temp_dir();
    const fs::path findings = fs::path(TETHASH_SOURCE_DIR) / "tests" / "data" / "fuzz";
    int count = 0;
    for (const auto& entry : fs::directory_iterator(findings)) {
        const fs::path p = entry.path();
        const std::string ext = p.extension().string();
        const bool surface = ext == ".ply" || ext == ".obj" || ext == ".stl" || ext == ".off";
        const std::string args =
            surface ? "tetrahedralize " + quote(p) + " -o " + quote(dir / "out.vtu") : "info " + quote(p);
        expect_bounded_error(args, {p.string()});
        ++count;
    }
    EXPECT_GT(count, 0);
}
