// `tethash detect --method portals --cells FILE`: the contacts of the default method with a cell file of two rooms
// and a door (and without one), the counters printed; a malformed cell file is refused (exit 2) naming the file and
// the line, for each kind of problem; --cells with another method is refused.
#include "cli_support.hpp"
#include "core_scenes.hpp"
#include "support.hpp"

#include <gtest/gtest.h>

using namespace tethash;
using namespace tethash::test;

namespace {

/// Two overlapping lattice objects across the plane x = 0.5, one file each.
std::string two_objects(const std::filesystem::path& dir)
{
    write_text(dir / "a.mesh", medit_text(lattice_object(3, 3, 3, 0.25, Eigen::Vector3d(0, 0, 0))));
    write_text(dir / "b.mesh", medit_text(lattice_object(3, 3, 3, 0.25, Eigen::Vector3d(0.375, 0.125, 0.3))));
    return quote(dir / "a.mesh") + " " + quote(dir / "b.mesh");
}

const char* const k_rooms = "# two rooms and a door\n"
                            "cell west -1 -1 -1 0.5 2 2\n"
                            "cell east 0.5 -1 -1 2 2 2   # beside it\n"
                            "\n"
                            "portal west east 0.5 0 0 0.5 0.5 1\n";

} // namespace

TEST(CliPortals, CellFileGivesTheDefaultsContacts)
{
    const auto dir = temp_dir();
    const std::string scene = two_objects(dir);
    const auto def = run_tethash("detect " + scene + " --threads 1 --contacts " + quote(dir / "default.csv"));
    ASSERT_EQ(def.status, 0) << def.err;
    const std::string want = read_text(dir / "default.csv");
    ASSERT_GT(csv_rows(want).size(), 10u);
    write_text(dir / "rooms.cells", k_rooms);
    for (const std::string& cells : {std::string(), " --cells " + quote(dir / "rooms.cells")}) {
        for (const char* threads : {"1", "2"}) {
            const auto r = run_tethash("detect " + scene + " --threads " + threads + " --method portals" + cells +
                                       " --contacts " + quote(dir / "portals.csv"));
            ASSERT_EQ(r.status, 0) << r.err;
            EXPECT_EQ(read_text(dir / "portals.csv"), want) << cells << " threads " << threads;
            EXPECT_NE(r.out.find("broad phase: portals"), std::string::npos) << r.out;
            if (!cells.empty()) {
                EXPECT_NE(r.out.find("portals: 2 cells"), std::string::npos) << r.out;
            }
        }
    }
    const auto all =
        run_tethash("detect " + scene + " --threads 1 --method all --repeat 1 --cells " + quote(dir / "rooms.cells"));
    ASSERT_EQ(all.status, 0) << all.err;
    EXPECT_NE(all.out.find("portals"), std::string::npos) << all.out;
}

TEST(CliPortals, MalformedCellFilesExit2NamingFileAndLine)
{
    const auto dir = temp_dir();
    const std::string scene = two_objects(dir);
    const std::string head = "cell west -1 -1 -1 0.5 2 2\ncell east 0.5 -1 -1 2 2 2\n";
    const std::pair<std::string, std::vector<std::string>> cases[] = {
        {"# nothing\n", {"bad.cells:", "no cell"}},
        {head + "room hall 0 0 0 1 1 1\n", {"bad.cells:3:", "expected 'cell' or 'portal'"}},
        {head + "cell hall 3 0 0 4 1\n", {"bad.cells:3:", "8 fields"}},
        {head + "cell hall 3 0 0 4 1 one\n", {"bad.cells:3:", "max z", "'one'"}},
        {head + "cell hall 3 0 0 4 1 inf\n", {"bad.cells:3:", "finite"}},
        {head + "cell hall 4 0 0 3 1 1\n", {"bad.cells:3:", "cell 'hall'", "inverted"}},
        {head + "cell hall 0 0 0 1 1 1\n", {"bad.cells:3:", "cell 'hall'", "overlaps cell 'west'"}},
        {head + "cell west 3 0 0 4 1 1\n", {"bad.cells:3:", "used twice"}},
        {head + "portal west hall 0.5 0 0 0.5 1 1\n", {"bad.cells:3:", "unknown cell 'hall'"}},
        {head + "cell far 5 0 0 6 1 1\nportal west far 0.5 0 0 0.5 1 1\n", {"bad.cells:4:", "share no face"}},
        {head + "portal west east 0.4 0 0 0.4 1 1\n", {"bad.cells:3:", "not on the shared face"}},
        {head + "portal west east 0.5 0 0 0.5 3 1\n", {"bad.cells:3:", "leaves the shared face"}},
        {head + "portal west east 0.5 0 0 0.5 1\n", {"bad.cells:3:", "9 fields"}},
        {head + "cell c planes 1 0 0 5  0 1 0 1  0 0 1 1\n", {"bad.cells:3:", "at least 4 planes"}},
        {head + "cell c planes 1 0 0 5  0 1 0 1  0 0 1 1  -1 0 0 -3\n", {"bad.cells:3:", "cell 'c'", "unbounded"}},
        {head + "cell c planes 1 0 0 5  0 1 0 1  0 0 1 1  -1 0 0 -3  0 -1 0 0  0 0 -1 x\n", {"bad.cells:3:", "'x'"}},
        {head + "cell c planes -1 0 0 0  1 0 0 1  0 -1 0 0  0 1 0 1  0 0 -1 0  0 0 1 1\n",
         {"bad.cells:3:", "cell 'c'", "overlaps cell 'west'"}},
        {head + "cell c surface missing.off\n", {"bad.cells:3:", "missing.off"}},
        {head + "portal west east polygon 0.5 0 0  0.5 1 0\n", {"bad.cells:3:", "at least 3 corners"}},
        {head + "portal west east polygon 0.5 0 0  0.5 1 0  0.5 0.25 0.25  0.5 0 1\n", {"bad.cells:3:", "not convex"}},
        {head + "portal west east polygon 0.5 0 0  0.5 1 0  0.6 1 1  0.5 0 1\n", {"bad.cells:3:", "not planar"}},
        {head + "portal west east polygon 0.5 0 0  0.5 3 0  0.5 3 1  0.5 0 1\n",
         {"bad.cells:3:", "not on the shared boundary", "outside cell"}},
        {head + "portal west east polygon 0.4 0 0  0.4 1 0  0.4 1 1  0.4 0 1\n",
         {"bad.cells:3:", "not on the shared boundary", "not on a face of cell 'west'"}},
    };
    for (const auto& [text, parts] : cases) {
        write_text(dir / "bad.cells", text);
        const auto r = run_tethash("detect " + scene + " --method portals --cells " + quote(dir / "bad.cells"));
        EXPECT_EQ(r.status, 2) << text << r.err;
        for (const std::string& part : parts)
            EXPECT_NE(r.err.find(part), std::string::npos) << "'" << part << "' not in: " << r.err;
    }
    expect_refused(run_tethash("detect " + scene + " --method portals --cells " + quote(dir / "missing.cells")),
                   {"missing.cells"});
    write_text(dir / "rooms.cells", k_rooms);
    expect_refused(run_tethash("detect " + scene + " --method bvh --cells " + quote(dir / "rooms.cells")),
                   {"--cells", "--method portals"});
}

namespace {

/// The box [lo, hi] as an OFF surface (outward triangles).
std::string box_off(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi)
{
    std::string out = "OFF\n8 12 0\n";
    for (int k = 0; k < 8; ++k)
        out += std::to_string(k & 1 ? hi.x() : lo.x()) + " " + std::to_string(k & 2 ? hi.y() : lo.y()) + " " +
               std::to_string(k & 4 ? hi.z() : lo.z()) + "\n";
    out += "3 0 2 6\n3 0 6 4\n3 1 5 7\n3 1 7 3\n3 0 4 5\n3 0 5 1\n3 2 3 7\n3 2 7 6\n3 0 1 3\n3 0 3 2\n3 4 6 7\n"
           "3 4 7 5\n";
    return out;
}

} // namespace

TEST(CliPortals, ObstaclesGiveTheCellsAndTheWallsOfEachVertex)
{
    const auto dir = temp_dir();
    const std::string scene = two_objects(dir); // across x = 0.5, inside [0, 1.125]^3
    // A wall across x = 0.5 with a door (y 0.25 .. 0.5) that both objects reach into, and a floor below them.
    write_text(dir / "w0.off", box_off({0.45, -0.5, -0.2}, {0.55, 0.25, 1.5}));
    write_text(dir / "w1.off", box_off({0.45, 0.5, -0.2}, {0.55, 1.5, 1.5}));
    write_text(dir / "w2.off", box_off({0.45, 0.25, 0.9}, {0.55, 0.5, 1.5}));
    write_text(dir / "floor.off", box_off({-0.5, -0.5, -0.2}, {1.5, 1.5, 0.1}));
    std::string walls;
    for (const char* w : {"w0.off", "w1.off", "w2.off", "floor.off"})
        walls += " --obstacle " + quote(dir / w);
    const auto def = run_tethash("detect " + scene + walls + " --threads 1 --contacts " + quote(dir / "default.csv"));
    if (def.status == 2 && def.err.find("assimp") != std::string::npos) GTEST_SKIP() << "built without assimp";
    ASSERT_EQ(def.status, 0) << def.err;
    const std::string want = read_text(dir / "default.csv");
    ASSERT_NE(want.find("w0.off"), std::string::npos); // some vertices are in the walls
    ASSERT_NE(want.find("floor.off"), std::string::npos);
    write_text(dir / "rooms.cells", k_rooms);
    for (const std::string& cells : {std::string(), " --cells " + quote(dir / "rooms.cells")}) {
        const auto r = run_tethash("detect " + scene + walls + " --threads 2 --method portals" + cells +
                                   " --contacts " + quote(dir / "portals.csv"));
        ASSERT_EQ(r.status, 0) << r.err;
        EXPECT_EQ(read_text(dir / "portals.csv"), want) << cells;
        EXPECT_NE(r.out.find("walls: each vertex against the obstacles meeting its cell"), std::string::npos) << r.out;
        EXPECT_EQ(r.out.find("cells from the obstacles") == std::string::npos, !cells.empty()) << r.out;
    }
}

TEST(CliPortals, ConvexCellsAndPolygonPortalsGiveTheDefaultsContacts)
{
    const auto dir = temp_dir();
    const std::string scene = two_objects(dir); // across x = 0.5, inside [0, 1.125]^3
    const auto def = run_tethash("detect " + scene + " --threads 1 --contacts " + quote(dir / "default.csv"));
    ASSERT_EQ(def.status, 0) << def.err;
    // The box [-1, 2] x [-1, 2] x [-1, 2] cut along the plane x + y = 1 into two convex cells, a triangle between them.
    write_text(dir / "diagonal.cells",
               "cell low planes -1 0 0 1  1 0 0 2  0 -1 0 1  0 1 0 2  0 0 -1 1  0 0 1 2  1 1 0 1\n"
               "cell high planes -1 0 0 1  1 0 0 2  0 -1 0 1  0 1 0 2  0 0 -1 1  0 0 1 2  -1 -1 0 -1\n"
               "portal low high polygon 0.5 0.5 0  0 1 0  0.25 0.75 1\n");
    for (const char* threads : {"1", "2"}) {
        const auto r = run_tethash("detect " + scene + " --threads " + threads + " --method portals --cells " +
                                   quote(dir / "diagonal.cells") + " --contacts " + quote(dir / "portals.csv"));
        ASSERT_EQ(r.status, 0) << r.err;
        EXPECT_EQ(read_text(dir / "portals.csv"), read_text(dir / "default.csv")) << threads;
        EXPECT_NE(r.out.find("portals: 2 cells"), std::string::npos) << r.out;
    }
    // An octahedron around the objects as a cell of a closed convex surface; with its bottom apex pushed in, refused.
    const auto octahedron = [](double bottom) {
        return "OFF\n6 8 0\n1.5 0.5 0.5\n0.5 1.5 0.5\n-0.5 0.5 0.5\n0.5 -0.5 0.5\n0.5 0.5 1.5\n0.5 0.5 " +
               std::to_string(bottom) + "\n3 0 1 4\n3 1 2 4\n3 2 3 4\n3 3 0 4\n3 1 0 5\n3 2 1 5\n3 3 2 5\n3 0 3 5\n";
    };
    write_text(dir / "gem.off", octahedron(-0.5));
    write_text(dir / "dent.off", octahedron(1));
    write_text(dir / "gem.cells", "# a gem\ncell gem surface gem.off\n");
    auto r = run_tethash("detect " + scene + " --threads 1 --method portals --cells " + quote(dir / "gem.cells") +
                         " --contacts " + quote(dir / "portals.csv"));
    if (r.status == 2 && r.err.find("assimp") != std::string::npos) GTEST_SKIP() << "built without assimp";
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_EQ(read_text(dir / "portals.csv"), read_text(dir / "default.csv"));
    write_text(dir / "dent.cells", "\ncell dent surface dent.off\n");
    expect_refused(run_tethash("detect " + scene + " --method portals --cells " + quote(dir / "dent.cells")),
                   {"dent.cells:2:", "cell 'dent'", "not convex"});
}
