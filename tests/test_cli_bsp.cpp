// `tethash detect --obstacle` and `tethash info SURFACE`: vertices inside polyhedral obstacles (closed, with depth
// and direction) in the contacts CSV, BSP statistics, refusal of open surfaces.
#include "cli_support.hpp"
#include "support.hpp"

#include <sstream>
#include <vector>

using namespace tethash::test;

namespace {

// The unit cube [0, 1]³, two triangles per side, outward.
const char* kCube = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nv 0 0 1\nv 1 0 1\nv 0 1 1\nv 1 1 1\n"
                    "f 1 5 7\nf 1 7 3\nf 2 4 8\nf 2 8 6\nf 1 2 6\nf 1 6 5\nf 3 7 8\nf 3 8 4\nf 1 3 4\nf 1 4 2\n"
                    "f 5 6 8\nf 5 8 7\n";

// One tet: vertex 1 inside the cube (0.25 above its base), vertex 2 on its face x = 1, vertices 3 and 4 outside.
const char* kTet = R"(MeshVersionFormatted 1
Dimension 3
Vertices
4
0.5 0.5 0.25 0
1 0.5 0.5 0
2 2 2 0
2 0 2 0
Tetrahedra
1
1 2 3 4 1
End
)";

} // namespace

TEST(CliBsp, DetectObstacleReportsInsideVerticesWithDepth)
{
    const auto dir = temp_dir();
    write_text(dir / "cube.obj", kCube);
    write_text(dir / "tet.mesh", kTet);
    const RunResult r = run_tethash("detect " + quote(dir / "tet.mesh") + " --obstacle " + quote(dir / "cube.obj") +
                                    " --contacts " + quote(dir / "c.csv"));
    if (r.status == 2 && r.err.find("assimp") != std::string::npos) GTEST_SKIP() << "built without assimp";
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_NE(r.out.find("2 vertices inside"), std::string::npos) << r.out;
    const auto rows = csv_rows(read_text(dir / "c.csv"));
    ASSERT_EQ(rows.size(), 3u); // header + two vertices
    ASSERT_EQ(rows[0].size(), 17u);
    EXPECT_EQ(rows[0][0], "vertex");
    EXPECT_EQ(rows[0][12], "obstacle");
    EXPECT_EQ(rows[0][13], "depth");
    // Vertex 0: inside, 0.25 above the base: pushed down.
    ASSERT_EQ(rows[1].size(), 17u);
    EXPECT_EQ(rows[1][0], "0");
    EXPECT_EQ(rows[1][1], ""); // no tet
    EXPECT_NE(rows[1][12].find("cube.obj"), std::string::npos);
    EXPECT_DOUBLE_EQ(std::stod(rows[1][13]), 0.25);
    EXPECT_DOUBLE_EQ(std::stod(rows[1][16]), -1.0);
    // Vertex 1: exactly on the face x = 1 counts as inside (closed), depth 0, direction the face normal.
    EXPECT_EQ(rows[2][0], "1");
    EXPECT_DOUBLE_EQ(std::stod(rows[2][13]), 0.0);
    EXPECT_DOUBLE_EQ(std::stod(rows[2][14]), 1.0);

    // Without --obstacle the CSV keeps its columns.
    const RunResult plain = run_tethash("detect " + quote(dir / "tet.mesh") + " --contacts " + quote(dir / "p.csv"));
    ASSERT_EQ(plain.status, 0) << plain.err;
    EXPECT_EQ(csv_rows(read_text(dir / "p.csv"))[0].size(), 12u);
}

TEST(CliBsp, InfoPrintsBspStatistics)
{
    const auto dir = temp_dir();
    write_text(dir / "cube.obj", kCube);
    RunResult r = run_tethash("info " + quote(dir / "cube.obj"));
    if (r.status == 2 && r.err.find("assimp") != std::string::npos) GTEST_SKIP() << "built without assimp";
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_NE(r.out.find("12 triangles, 6 planes"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("6 nodes, 1 IN leaves, 6 OUT leaves, depth 6"), std::string::npos) << r.out;
    r = run_tethash("info --json " + quote(dir / "cube.obj"));
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_NE(r.out.find("\"nodes\": 6"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("\"planes\": 6"), std::string::npos) << r.out;

    // The shipped bowl: concave, its four rim quads in one plane.
    r = run_tethash("info " + quote(std::filesystem::path(TETHASH_SOURCE_DIR) / "meshes/surfaces/bowl.obj"));
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_NE(r.out.find("28 triangles, 11 planes"), std::string::npos) << r.out;
}

TEST(CliBsp, OpenOrSelfIntersectingSurfacesAreRefused)
{
    const auto dir = temp_dir();
    std::string open = kCube;
    open.resize(open.rfind("f 5 8 7"));
    write_text(dir / "open.obj", open);
    write_text(dir / "tet.mesh", kTet);
    RunResult r = run_tethash("info " + quote(dir / "open.obj"));
    if (r.status == 2 && r.err.find("assimp") != std::string::npos) GTEST_SKIP() << "built without assimp";
    EXPECT_EQ(r.status, 2);
    EXPECT_NE(r.err.find("open surface: edge"), std::string::npos) << r.err;
    r = run_tethash("detect " + quote(dir / "tet.mesh") + " --obstacle " + quote(dir / "open.obj"));
    EXPECT_EQ(r.status, 2);
    EXPECT_NE(r.err.find("--obstacle"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("open surface"), std::string::npos) << r.err;

    // Two overlapping cubes in one file.
    std::string two = kCube;
    two += "v 0.5 0.5 0.5\nv 1.5 0.5 0.5\nv 0.5 1.5 0.5\nv 1.5 1.5 0.5\nv 0.5 0.5 1.5\nv 1.5 0.5 1.5\nv 0.5 1.5 1.5\n"
           "v 1.5 1.5 1.5\n";
    std::istringstream faces(kCube);
    for (std::string line; std::getline(faces, line);) {
        if (line[0] != 'f') continue;
        int a = 0, b = 0, c = 0;
        std::sscanf(line.c_str(), "f %d %d %d", &a, &b, &c);
        two += "f " + std::to_string(a + 8) + " " + std::to_string(b + 8) + " " + std::to_string(c + 8) + "\n";
    }
    write_text(dir / "two.obj", two);
    r = run_tethash("info " + quote(dir / "two.obj"));
    EXPECT_EQ(r.status, 2);
    EXPECT_NE(r.err.find("self-intersecting surface"), std::string::npos) << r.err;

    // A scene with an open collider = "bsp" surface: refused before the run, naming the object.
    write_text(dir / "s.toml", "steps = 2\n[output]\nevery = 0\n[[object]]\nname = \"lid\"\nmesh = \"open.obj\"\n"
                               "static = true\ncollider = \"bsp\"\n[[object]]\ngenerate = { shape = \"box\", "
                               "resolution = 2 }\ntranslate = [0.5, 0.5, 2]\n");
    r = run_tethash("simulate " + quote(dir / "s.toml") + " --out " + quote(dir / "out"));
    EXPECT_EQ(r.status, 2);
    EXPECT_NE(r.err.find("object 'lid'"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("open surface"), std::string::npos) << r.err;
}
