// `tethash detect --continuous FRAME0 FRAME1`: a tet passing through another between two frames (no contact in
// either frame) is reported with its time of impact, written as CSV; bad input refused.
#include "cli_support.hpp"
#include "support.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <string>

using namespace tethash::test;
namespace fs = std::filesystem;

namespace {

/// Two unit corner tets in one Medit file: A at the origin, B shifted by `bx` along x.
std::string two_tets(double bx)
{
    std::string s = "MeshVersionFormatted 1\nDimension 3\nVertices\n8\n"
                    "0 0 0 0\n1 0 0 0\n0 1 0 0\n0 0 1 0\n";
    for (const char* corner : {"0.2 0.2 0.2", "1.2 0.2 0.2", "0.2 1.2 0.2", "0.2 0.2 1.2"}) {
        double x = 0, y = 0, z = 0;
        std::sscanf(corner, "%lf %lf %lf", &x, &y, &z);
        s += std::to_string(x + bx) + " " + std::to_string(y) + " " + std::to_string(z) + " 0\n";
    }
    s += "Tetrahedra\n2\n1 2 3 4 1\n5 6 7 8 1\nEnd\n";
    return s;
}

} // namespace

TEST(CliContinuous, ReportsAPassThroughWithItsTimeOfImpact)
{
    const fs::path dir = temp_dir();
    write_text(dir / "f0.mesh", two_tets(-3));
    write_text(dir / "f1.mesh", two_tets(3));
    // Neither frame has a contact.
    for (const char* frame : {"f0.mesh", "f1.mesh"}) {
        const RunResult d = run_tethash("detect " + quote(dir / frame));
        ASSERT_EQ(d.status, 0) << d.err;
        EXPECT_NE(d.out.find("contacts: 0"), std::string::npos) << d.out;
    }
    const RunResult r = run_tethash("detect --continuous " + quote(dir / "f0.mesh") + " " + quote(dir / "f1.mesh") +
                                    " --contacts " + quote(dir / "c.csv"));
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_NE(r.out.find("contacts: "), std::string::npos) << r.out;
    EXPECT_EQ(r.out.find("contacts: 0"), std::string::npos) << r.out;
    const auto rows = csv_rows(read_text(dir / "c.csv"));
    ASSERT_GE(rows.size(), 2u);
    EXPECT_EQ(rows[0], (std::vector<std::string>{"kind", "a0", "a1", "b0", "b1", "b2", "a_object", "b_object", "toi"}));
    double earliest = 1;
    bool vertex_face = false, edge_edge = false;
    for (std::size_t i = 1; i < rows.size(); ++i) {
        ASSERT_EQ(rows[i].size(), 9u);
        vertex_face = vertex_face || rows[i][0] == "vertex-face";
        edge_edge = edge_edge || rows[i][0] == "edge-edge";
        earliest = std::min(earliest, std::stod(rows[i][8]));
    }
    EXPECT_TRUE(vertex_face && edge_edge);
    // B (shifted by bx = -3 + 6 t) comes from the left: its corner (1.2 + bx, 0.2, 0.2) reaches A's face x = 0 at
    // bx = -1.2, t = 0.3 (up to the rounding of the frames' coordinates).
    EXPECT_LE(earliest, 0.3 + 1e-12);
    EXPECT_GT(earliest, 0.3 - 1e-5);
    // One object: --no-self leaves nothing.
    const RunResult no_self =
        run_tethash("detect --continuous --no-self " + quote(dir / "f0.mesh") + " " + quote(dir / "f1.mesh"));
    ASSERT_EQ(no_self.status, 0) << no_self.err;
    EXPECT_NE(no_self.out.find("contacts: 0"), std::string::npos) << no_self.out;
}

TEST(CliContinuous, BadInputIsRefused)
{
    const fs::path dir = temp_dir();
    write_text(dir / "f0.mesh", two_tets(-3));
    write_text(dir / "one.mesh", "MeshVersionFormatted 1\nDimension 3\nVertices\n4\n0 0 0 0\n1 0 0 0\n0 1 0 0\n0 0 1 "
                                 "0\nTetrahedra\n1\n1 2 3 4 1\nEnd\n");
    const std::string f0 = quote(dir / "f0.mesh");
    expect_refused(run_tethash("detect --continuous " + f0), {"--continuous", "two frames", "1 files"});
    expect_refused(run_tethash("detect --continuous " + f0 + " " + quote(dir / "one.mesh")),
                   {"one.mesh", "4 vertices", "the same meshes"});
    expect_refused(run_tethash("detect --continuous " + f0 + " " + f0 + " --contacts " + quote(dir / "c.vtu")),
                   {"--contacts", ".csv"});
    expect_refused(run_tethash("detect --continuous " + f0 + " " + f0 + " --method all"), {"--method all"});
    expect_refused(run_tethash("detect --continuous " + f0 + " " + quote(dir / "absent.mesh")), {"absent.mesh"});
}
