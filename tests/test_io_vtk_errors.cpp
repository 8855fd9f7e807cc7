// Broken .vtk and .vtu files: every class of bad input gets an Error naming the file, the line
// (or byte offset) and what was expected.
#include "support.hpp"

#include "tethash/error.hpp"
#include "tethash/io/pvd.hpp"
#include "tethash/io/vtk_legacy.hpp"
#include "tethash/io/vtu.hpp"

#include <functional>
#include <unistd.h>

using namespace tethash;
using namespace tethash::test;

namespace {

/// Replaces the first occurrence of `from` (which must occur) by `to`.
std::string replaced(std::string s, const std::string& from, const std::string& to)
{
    const auto p = s.find(from);
    EXPECT_NE(p, std::string::npos) << "test bug: '" << from << "' not in the template";
    if (p != std::string::npos) s.replace(p, from.size(), to);
    return s;
}

// Line numbers below are 1-based lines of these templates.
const std::string kVtk = "# vtk DataFile Version 3.0\n" // 1
                         "four points\n"                // 2
                         "ASCII\n"                      // 3
                         "DATASET UNSTRUCTURED_GRID\n"  // 4
                         "POINTS 4 double\n"            // 5
                         "0 0 0\n"                      // 6
                         "1 0 0\n"                      // 7
                         "0 1 0\n"                      // 8
                         "0 0 1\n"                      // 9
                         "CELLS 1 5\n"                  // 10
                         "4 0 1 2 3\n"                  // 11
                         "CELL_TYPES 1\n"               // 12
                         "10\n";                        // 13

const std::string kVtu = "<?xml version=\"1.0\"?>\n"                                                         // 1
                         "<VTKFile type=\"UnstructuredGrid\" version=\"0.1\" byte_order=\"LittleEndian\">\n" // 2
                         "  <UnstructuredGrid>\n"                                                            // 3
                         "    <Piece NumberOfPoints=\"4\" NumberOfCells=\"1\">\n"                            // 4
                         "      <Points>\n"                                                                  // 5
                         "        <DataArray type=\"Float64\" NumberOfComponents=\"3\" format=\"ascii\">\n"  // 6
                         "          0 0 0\n"                                                                 // 7
                         "          1 0 0\n"                                                                 // 8
                         "          0 1 0\n"                                                                 // 9
                         "          0 0 1\n"                                                                 // 10
                         "        </DataArray>\n"                                                            // 11
                         "      </Points>\n"                                                                 // 12
                         "      <Cells>\n"                                                                   // 13
                         "        <DataArray type=\"Int32\" Name=\"connectivity\" format=\"ascii\">\n"       // 14
                         "          0 1 2 3\n"                                                               // 15
                         "        </DataArray>\n"                                                            // 16
                         "        <DataArray type=\"Int32\" Name=\"offsets\" format=\"ascii\">\n"            // 17
                         "          4\n"                                                                     // 18
                         "        </DataArray>\n"                                                            // 19
                         "        <DataArray type=\"UInt8\" Name=\"types\" format=\"ascii\">\n"              // 20
                         "          10\n"                                                                    // 21
                         "        </DataArray>\n"                                                            // 22
                         "      </Cells>\n"                                                                  // 23
                         "    </Piece>\n"                                                                    // 24
                         "  </UnstructuredGrid>\n"                                                           // 25
                         "</VTKFile>\n";                                                                     // 26

/// Shell-quoted path (built in steps: GCC 12 warns falsely about `"'" + s + "'"` once inlined here).
std::string shell_quoted(const std::filesystem::path& p)
{
    std::string r = "'";
    r += p.string();
    r += '\'';
    return r;
}

struct Case {
    const char* name;
    std::string text;
    std::vector<std::string> parts; ///< after the file name
};

/// Writes each case to dir/NAME`ext` and expects `read` to fail on it with the case's message (its first part
/// prefixed with the path).
void expect_cases(const std::filesystem::path& dir, const std::vector<Case>& cases, const std::string& ext,
                  const std::function<void(const std::string&)>& read)
{
    for (const Case& c : cases) {
        SCOPED_TRACE(c.name);
        const auto path = dir / (std::string(c.name) + ext);
        write_text(path, c.text);
        std::vector<std::string> parts = c.parts;
        parts.front() = path.string() + parts.front();
        expect_error([&] { read(path.string()); }, parts);
    }
}

} // namespace

TEST(IoVtkErrors, TemplatesAreValid)
{
    const auto dir = temp_dir();
    write_text(dir / "ok.vtk", kVtk);
    write_text(dir / "ok.vtu", kVtu);
    EXPECT_EQ(io::read_vtk((dir / "ok.vtk").string()).num_tets(), 1);
    EXPECT_EQ(io::read_vtu((dir / "ok.vtu").string()).num_tets(), 1);
}

TEST(IoVtkErrors, LegacyAscii)
{
    const auto dir = temp_dir();
    const std::vector<Case> cases = {
        {"truncated",
         kVtk.substr(0, kVtk.find("0 1 0\n")),
         {":7: expected 12 values of POINTS (4 points × 3), found end of file after 6"}},
        {"unknown_version", replaced(kVtk, "Version 3.0", "Version 6.0"), {":1: unknown legacy VTK version '6.0'"}},
        {"not_vtk", "hello\n" + kVtk, {":1: expected '# vtk DataFile Version X.Y', found 'hello'"}},
        {"format", replaced(kVtk, "ASCII", "UTF8"), {":3: expected ASCII or BINARY, found 'UTF8'"}},
        {"dataset",
         replaced(kVtk, "UNSTRUCTURED_GRID", "POLYDATA"),
         {":4: expected UNSTRUCTURED_GRID", "found 'POLYDATA'"}},
        {"type",
         replaced(kVtk, "POINTS 4 double", "POINTS 4 half"),
         {":5: expected the data type of POINTS", "found 'half'"}},
        {"nan", replaced(kVtk, "0 1 0\n", "0 nan 0\n"), {":8: point 2 has a non-finite coordinate"}},
        {"inf", replaced(kVtk, "0 0 1\n", "0 0 -inf\n"), {":9: point 3 has a non-finite coordinate"}},
        {"index",
         replaced(kVtk, "4 0 1 2 3", "4 0 1 2 9"),
         {":11: tet 0 (cell 0) refers to point 9, but the file has only 4 points"}},
        {"negative_index", replaced(kVtk, "4 0 1 2 3", "4 0 -1 2 3"), {":11: tet 0 (cell 0) refers to point -1"}},
        {"too_few_points",
         replaced(kVtk, "POINTS 4 double", "POINTS 5 double"),
         {":10: expected a number (value 13 of 15 of POINTS (5 points × 3)), found 'CELLS'"}},
        {"cell_types_count",
         replaced(kVtk, "CELL_TYPES 1", "CELL_TYPES 2"),
         {":12: expected CELL_TYPES 1 (the number of CELLS), found 2"}},
        {"cells_size",
         replaced(kVtk, "CELLS 1 5", "CELLS 1 6"),
         {":12: expected an integer (value 6 of 6 of CELLS", "found 'CELL_TYPES'"}},
        {"cell_count",
         replaced(kVtk, "4 0 1 2 3", "5 0 1 2 3"),
         {":11: cell 0 has 5 points, but only 4 values remain"}},
        {"tet_with_3",
         replaced(replaced(kVtk, "CELLS 1 5", "CELLS 1 4"), "4 0 1 2 3", "3 0 1 2"),
         {":13: cell 0 has type 10 (tetra) but 3 points, expected 4"}},
        {"no_types", kVtk.substr(0, kVtk.find("CELL_TYPES")), {":11: expected CELL_TYPES, found end of file"}},
        {"keyword", kVtk + "POLYGONS 1 4\n", {":14: expected a section keyword", "found 'POLYGONS'"}},
        {"point_data_count", kVtk + "POINT_DATA 3\n", {":14: expected POINT_DATA 4 (the number of points), found 3"}},
        {"offsets_layout",
         replaced(kVtk, "CELLS 1 5\n4 0 1 2 3\n",
                  "CELLS 2 4\nOFFSETS vtktypeint64\n0 5\nCONNECTIVITY vtktypeint64\n0 1 2 3\n"),
         {":12: offset 1 is 5, expected a value from 0 to 4"}},
    };
    expect_cases(dir, cases, ".vtk", [](const std::string& path) { (void)io::read_vtk(path); });
}

TEST(IoVtkErrors, LegacyBinaryNamesByteOffsets)
{
    const auto dir = temp_dir();
    write_text(dir / "ok.vtk", kVtk);
    const TetMesh m = io::read_vtk((dir / "ok.vtk").string());
    io::write_vtk((dir / "b.vtk").string(), m, {}, true);
    const std::string bin = read_text(dir / "b.vtk");
    const std::size_t data = bin.find("POINTS 4 double\n") + 16;
    write_text(dir / "cut.vtk", bin.substr(0, data + 50));
    expect_error([&] { io::read_vtk((dir / "cut.vtk").string()); },
                 {(dir / "cut.vtk").string() + ": byte " + std::to_string(data) +
                  ": expected 96 bytes of POINTS (4 points × 3) (12 values), found only 50"});
    // A point id past the end, in big-endian int32 after "CELLS 1 5\n" and the count 4.
    std::string bad = bin;
    const std::size_t cells = bad.find("CELLS 1 5\n") + 10;
    bad[cells + 4 + 3 * 4 + 3] = 7; // the fourth id (low byte) becomes 7
    write_text(dir / "index.vtk", bad);
    expect_error(
        [&] { io::read_vtk((dir / "index.vtk").string()); },
        {(dir / "index.vtk").string() + ": byte " + std::to_string(cells + 16) + ": tet 0 (cell 0) refers to point 7"});
    // NaN in binary points.
    std::string nan = bin;
    const double q = std::nan("");
    unsigned char b[8];
    std::memcpy(b, &q, 8);
    for (int i = 0; i < 8; ++i)
        nan[data + 3 * 8 + 8 + i] = static_cast<char>(b[7 - i]); // point 1, y
    write_text(dir / "nan.vtk", nan);
    expect_error(
        [&] { io::read_vtk((dir / "nan.vtk").string()); },
        {(dir / "nan.vtk").string() + ": byte " + std::to_string(data + 32) + ": point 1 has a non-finite coordinate"});
}

TEST(IoVtkErrors, VtuAscii)
{
    const auto dir = temp_dir();
    const std::vector<Case> cases = {
        {"truncated",
         kVtu.substr(0, kVtu.find("        </DataArray>\n      </Cells>")),
         {":21: expected </DataArray>, found end of file"}},
        {"mismatched", replaced(kVtu, "</Points>", "</Cells>"), {":12: expected </Points>, found </Cells>"}},
        {"unknown_version",
         replaced(kVtu, "version=\"0.1\"", "version=\"3.0\""),
         {":2: unknown VTK XML version \"3.0\""}},
        {"polydata",
         replaced(kVtu, "type=\"UnstructuredGrid\"", "type=\"PolyData\""),
         {":2: expected type=\"UnstructuredGrid\"", "found \"PolyData\""}},
        {"type", replaced(kVtu, "Float64", "Float16"), {":6: expected the type of the points", "found \"Float16\""}},
        {"format",
         replaced(kVtu, "UInt8\" Name=\"types\" format=\"ascii\"", "UInt8\" Name=\"types\" format=\"hex\""),
         {":20: expected format=\"ascii\", \"binary\" or \"appended\"", "found \"hex\""}},
        {"too_few_points",
         replaced(kVtu, "NumberOfPoints=\"4\"", "NumberOfPoints=\"5\""),
         {":10: expected 15 values in the points (5 × 3 values), found 12"}},
        {"too_many_points",
         replaced(kVtu, "NumberOfPoints=\"4\"", "NumberOfPoints=\"3\""),
         {":10: expected 9 values in the points (3 × 3 values), found 12"}},
        {"bad_count_attr",
         replaced(kVtu, "NumberOfCells=\"1\"", "NumberOfCells=\"one\""),
         {":4: expected NumberOfCells in <Piece> to be an integer", "found \"one\""}},
        {"nan",
         replaced(kVtu, "          0 1 0\n", "          0 NaN 0\n"),
         {":9: point 2 has a non-finite coordinate"}},
        {"not_a_number",
         replaced(kVtu, "          1 0 0\n", "          1 x 0\n"),
         {":8: expected a number (value 4 of the points", "found 'x'"}},
        {"index",
         replaced(kVtu, "0 1 2 3", "0 1 2 4"),
         {":15: tet 0 (cell 0) refers to point 4, but the piece has only 4 points"}},
        {"offsets",
         replaced(kVtu, "          4\n", "          5\n"),
         {":15: expected 5 values in DataArray 'connectivity' (5 values, the last offset), found 4"}},
        {"tet_size",
         replaced(replaced(kVtu, "          4\n", "          3\n"), "0 1 2 3", "0 1 2"),
         {":21: cell 0 has type 10 (tetra) but 3 points, expected 4"}},
        {"no_types",
         replaced(kVtu, "Name=\"types\"", "Name=\"kinds\""),
         {":13: expected a DataArray Name=\"types\" in <Cells>"}},
        {"points_components",
         replaced(kVtu, "NumberOfComponents=\"3\"", "NumberOfComponents=\"2\""),
         {":6: expected NumberOfComponents=\"3\" for the points, found \"2\""}},
        {"compressor",
         replaced(kVtu, "byte_order=", "compressor=\"vtkLZ4DataCompressor\" byte_order="),
         {":2: unsupported compressor \"vtkLZ4DataCompressor\""}},
        {"header_type",
         replaced(kVtu, "byte_order=", "header_type=\"UInt16\" byte_order="),
         {":2: expected header_type=\"UInt32\" or \"UInt64\", found \"UInt16\""}},
        {"base64_char",
         replaced(kVtu, "format=\"ascii\">\n          0 1 2 3",
                  "format=\"binary\">\n          EAAAAA*AAAABAAAAAgAAAAMAAAA="),
         {":14: DataArray 'connectivity'", "invalid character '*' in base64 data"}},
        {"base64_short",
         replaced(kVtu, "format=\"ascii\">\n          0 1 2 3",
                  "format=\"binary\">\n          EAAAAAAAAAABAAAAAgAAAA=="),
         {":14: expected 16 bytes of data of DataArray 'connectivity'",
          "found the end of the base64 text after 16 decoded bytes"}},
        {"base64_header",
         replaced(kVtu, "format=\"ascii\">\n          0 1 2 3",
                  "format=\"binary\">\n          FAAAAAAAAAABAAAAAgAAAAMAAAA="),
         {":14: expected the block header of DataArray 'connectivity'", "to give 16 bytes, found 20"}},
    };
    expect_cases(dir, cases, ".vtu", [](const std::string& path) { (void)io::read_vtu(path); });
    // The base64 form of the template's connectivity, as a check of the strings above.
    write_text(dir / "b64.vtu", replaced(kVtu, "format=\"ascii\">\n          0 1 2 3",
                                         "format=\"binary\">\n          EAAAAA==AAAAAAEAAAACAAAAAwAAAA=="));
    EXPECT_EQ(io::read_vtu((dir / "b64.vtu").string()).tets(0, 3), 3);
}

TEST(IoVtkErrors, VtuAppendedRawNamesByteOffsets)
{
    const auto dir = temp_dir();
    write_text(dir / "ok.vtu", kVtu);
    const TetMesh m = io::read_vtu((dir / "ok.vtu").string());
    io::write_vtu((dir / "w.vtu").string(), m);
    const std::string text = read_text(dir / "w.vtu");
    const std::size_t start = text.find('_', text.find("<AppendedData")) + 1;
    // The data are in reverse document order: types (4 + 1 bytes), offsets (4 + 4), connectivity
    // (4 + 16), then the points (4 + 96) at offset 33.
    write_text(dir / "cut_header.vtu", text.substr(0, start + 33 + 2));
    expect_error([&] { io::read_vtu((dir / "cut_header.vtu").string()); },
                 {(dir / "cut_header.vtu").string() + ": byte " + std::to_string(start + 33) +
                      ": expected 4 bytes of the block header of the points (4 × 3 values)",
                  "found only 2 before the end of the file"});
    write_text(dir / "cut_data.vtu", text.substr(0, start + 33 + 50));
    expect_error([&] { io::read_vtu((dir / "cut_data.vtu").string()); },
                 {(dir / "cut_data.vtu").string() + ": byte " + std::to_string(start + 37) +
                      ": expected 96 bytes of data of the points (4 × 3 values)",
                  "found only 46 before the end of the file"});
    std::string wrong = text;
    wrong[start] = 9; // header of 'types' says 9 bytes
    write_text(dir / "header.vtu", wrong);
    expect_error([&] { io::read_vtu((dir / "header.vtu").string()); },
                 {(dir / "header.vtu").string() + ": byte " + std::to_string(start) +
                  ": expected the block header of DataArray 'types' (1 cells) to give 1 bytes, found 9"});
    const std::string offs = replaced(text, "offset=\"0\"", "offset=\"100000\"");
    write_text(dir / "offset.vtu", offs);
    expect_error([&] { io::read_vtu((dir / "offset.vtu").string()); },
                 {(dir / "offset.vtu").string() + ":", "past its end"});
}

TEST(IoVtkErrors, CliInfoExitsWithStatus2)
{
    if (run_tethash("info --help").status != 0) GTEST_SKIP() << "tethash info is not there yet";
    const auto dir = temp_dir();
    write_text(dir / "bad.vtk", replaced(kVtk, "4 0 1 2 3", "4 0 1 2 9"));
    const RunResult r = run_tethash("info " + shell_quoted(dir / "bad.vtk"));
    expect_refused(r, {"bad.vtk:11: tet 0 (cell 0) refers to point 9"});
    write_text(dir / "bad.vtu", replaced(kVtu, "version=\"0.1\"", "version=\"9.0\""));
    const RunResult u = run_tethash("info " + shell_quoted(dir / "bad.vtu"));
    expect_refused(u, {"bad.vtu:2: unknown VTK XML version"});
}

TEST(IoVtkErrors, EveryTruncationAndByteFlipGivesAnErrorOrAMesh)
{
    // Cut our own files at every length and flip bytes at fixed pseudo-random places: the readers
    // must either read a mesh or throw tethash::Error (never crash or throw anything else).
    const auto dir = temp_dir();
    write_text(dir / "ok.vtk", kVtk);
    const TetMesh m = io::read_vtk((dir / "ok.vtk").string());
    io::Fields f;
    f.point.push_back({"velocity", 3, std::vector<double>(12, 0.5)});
    io::write_vtk((dir / "b.vtk").string(), m, f, true);
    io::write_vtk((dir / "a.vtk").string(), m, f, false);
    io::write_vtu((dir / "r.vtu").string(), m, f);
    write_text(dir / "t.vtu", kVtu);
    std::uint32_t seed = 12345;
    const auto next = [&] { return seed = seed * 1664525u + 1013904223u; };
    for (const char* name : {"b.vtk", "a.vtk", "r.vtu", "t.vtu"}) {
        const std::string text = read_text(dir / name);
        const bool vtu = std::string(name).ends_with(".vtu");
        // Thousands of tiny files: a memory file system where there is one.
        const auto scratch = std::filesystem::is_directory("/dev/shm") ? std::filesystem::path("/dev/shm") : dir;
        const auto path = scratch / ("tethash_test_" + std::to_string(::getpid()) + "_broken_" + name);
        const auto attempt = [&](const std::string& content, const std::string& what) {
            write_text(path, content);
            try {
                const TetMesh r = vtu ? io::read_vtu(path.string()) : io::read_vtk(path.string());
                r.check_consistency(what);
            } catch (const Error&) {
            } catch (const std::exception& e) {
                ADD_FAILURE() << name << " " << what << ": " << e.what();
            }
        };
        for (std::size_t len = 0; len < text.size(); len += len < 300 ? 1 : 3)
            attempt(text.substr(0, len), "cut at " + std::to_string(len));
        for (int i = 0; i < 300; ++i) {
            std::string t = text;
            const std::size_t pos = next() % t.size();
            t[pos] = static_cast<char>(next() & 0xff);
            attempt(t, "byte " + std::to_string(pos) + " changed");
        }
        std::filesystem::remove(path);
    }
}
