// `tethash detect --edges`: a needle through a flat tet (no vertex inside either) is reported as edge-face contacts,
// written as CSV with its documented columns; object rules apply; bad combinations are refused (exit 2).
#include "cli_support.hpp"
#include "support.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <string>

using namespace tethash::test;
namespace fs = std::filesystem;

namespace {

std::string one_tet(const char* corners)
{
    return std::string("MeshVersionFormatted 1\nDimension 3\nVertices\n4\n") + corners +
           "Tetrahedra\n1\n1 2 3 4 1\nEnd\n";
}

/// A: a flat tet over the unit corner triangle; B: a thin needle from z = -1 to z = 1 through A's middle.
void write_scene(const fs::path& dir)
{
    write_text(dir / "flat.mesh", one_tet("0 0 0 0\n1 0 0 0\n0 1 0 0\n0.3 0.3 0.05 0\n"));
    write_text(dir / "needle.mesh", one_tet("0.2 0.2 -1 0\n0.25 0.2 -1 0\n0.2 0.25 -1 0\n0.22 0.22 1 0\n"));
}

} // namespace

TEST(CliEdgeContacts, ReportsANeedleThroughAFlatTet)
{
    const fs::path dir = temp_dir();
    write_scene(dir);
    const std::string scene = quote(dir / "flat.mesh") + " " + quote(dir / "needle.mesh");
    const RunResult r = run_tethash("detect " + scene + " --edge-contacts " + quote(dir / "e.csv"));
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_NE(r.out.find("contacts: 0\n"), std::string::npos) << r.out; // no vertex inside a tet
    EXPECT_NE(r.out.find("edge-face contacts: "), std::string::npos) << r.out;
    const auto rows = csv_rows(read_text(dir / "e.csv"));
    ASSERT_GE(rows.size(), 4u); // the needle's 3 long edges cross A's bottom, each crosses a top face too
    EXPECT_EQ(rows[0], (std::vector<std::string>{"e0",          "e1",          "f0",         "f1",         "f2",
                                                 "edge_object", "face_object", "edge_file",  "e0_in_file", "e1_in_file",
                                                 "face_file",   "f0_in_file",  "f1_in_file", "f2_in_file", "t",
                                                 "b0",          "b1",          "b2",         "inner_end",  "n0",
                                                 "n1",          "n2"}));
    int needle_through_flat = 0;
    for (std::size_t i = 1; i < rows.size(); ++i) {
        ASSERT_EQ(rows[i].size(), 22u);
        if (rows[i][5] != "1") continue;
        ++needle_through_flat;
        EXPECT_EQ(rows[i][6], "0");
        EXPECT_EQ(rows[i][7], "1");
        EXPECT_EQ(rows[i][10], "0");
        // Medit ids are 1-based in the file: the needle's vertices 4..7 in the scene are 1..4 in needle.mesh.
        EXPECT_EQ(std::stoi(rows[i][8]), std::stoi(rows[i][0]) - 3);
        const double t = std::stod(rows[i][14]);
        EXPECT_GT(t, 0.0);
        EXPECT_LT(t, 1.0);
        const double n = std::hypot(std::stod(rows[i][19]), std::stod(rows[i][20]), std::stod(rows[i][21]));
        EXPECT_NEAR(n, 1.0, 1e-12);
    }
    EXPECT_GE(needle_through_flat, 3);
    // Both objects static: nothing; --no-self: the same (the crossings are between objects).
    const RunResult both_static = run_tethash("detect " + scene + " --edges --static 0,1");
    ASSERT_EQ(both_static.status, 0) << both_static.err;
    EXPECT_NE(both_static.out.find("edge-face contacts: 0 "), std::string::npos) << both_static.out;
    const RunResult no_self = run_tethash("detect " + scene + " --edges --no-self");
    ASSERT_EQ(no_self.status, 0) << no_self.err;
    EXPECT_EQ(no_self.out.find("edge-face contacts: 0 "), std::string::npos) << no_self.out;
}

TEST(CliEdgeContacts, BadCombinationsAreRefused)
{
    const fs::path dir = temp_dir();
    write_scene(dir);
    const std::string scene = quote(dir / "flat.mesh") + " " + quote(dir / "needle.mesh");
    expect_refused(run_tethash("detect " + scene + " --edge-contacts " + quote(dir / "e.txt")),
                   {"--edge-contacts", "e.txt", "expected .csv"});
    expect_refused(run_tethash("detect " + scene + " --edges --method all"), {"--edges", "--method all"});
    expect_refused(run_tethash("detect --continuous " + scene + " --edges"), {"--edges", "--continuous"});
    expect_refused(run_tethash("detect " + scene + " --edge-contacts " + quote(dir / "missing" / "e.csv")),
                   {"--edge-contacts"});
}
