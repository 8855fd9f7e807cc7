// `tethash info`: counts and problems, JSON for scripts, every shared real mesh, bad input.
#include "support.hpp"

#include <regex>

using namespace tethash::test;

namespace {

/// Integer value of "key": N in a JSON text (first occurrence), or -1.
long json_int(const std::string& json, const std::string& key)
{
    std::smatch m;
    if (std::regex_search(json, m, std::regex("\"" + key + "\": (-?[0-9]+)"))) return std::stol(m[1]);
    return -1;
}

// One positively oriented tet, one inverted tet, one flat tet and an unreferenced vertex, in Medit format.
const char* kProblemMesh = R"(MeshVersionFormatted 1
Dimension 3
Vertices
8
0 0 0 0
1 0 0 0
0 1 0 0
0 0 1 0
2 0 0 0
3 0 0 0
4 0 0 0
9 9 9 0
Tetrahedra
3
1 2 3 4 1
1 3 2 4 1
1 2 5 6 2
End
)";

} // namespace

TEST(CliInfo, ReportsProblemsInJson)
{
    const auto dir = temp_dir();
    write_text(dir / "problems.mesh", kProblemMesh);
    const RunResult r = run_tethash("info --json " + quote(dir / "problems.mesh"));
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_EQ(json_int(r.out, "vertices"), 8);
    EXPECT_EQ(json_int(r.out, "tets"), 3);
    EXPECT_EQ(json_int(r.out, "objects"), 1);
    EXPECT_EQ(json_int(r.out, "inverted_tets"), 1);
    EXPECT_EQ(json_int(r.out, "degenerate_tets"), 1);
    EXPECT_EQ(json_int(r.out, "unreferenced_vertices"), 2); // vertices 7 and 8 (1-based)
}

TEST(CliInfo, TextSummaryNamesProblems)
{
    const auto dir = temp_dir();
    write_text(dir / "problems.mesh", kProblemMesh);
    const RunResult r = run_tethash("info " + quote(dir / "problems.mesh"));
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_NE(r.out.find("vertices 8"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("1 inverted tets"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("2 unreferenced vertices"), std::string::npos) << r.out;
}

TEST(CliInfo, SeveralFilesAreOneSceneWithObjects)
{
    const auto dir = temp_dir();
    write_text(dir / "a.mesh", kProblemMesh);
    const RunResult r = run_tethash("info --json " + quote(dir / "a.mesh") + " " + quote(dir / "a.mesh"));
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_EQ(json_int(r.out, "vertices"), 16);
    EXPECT_EQ(json_int(r.out, "tets"), 6);
    EXPECT_EQ(json_int(r.out, "objects"), 2);
    EXPECT_NE(r.out.find("\"files\""), std::string::npos);
}

TEST(CliInfo, MissingFileAndUnknownFormatExitTwo)
{
    const auto dir = temp_dir();
    RunResult r = run_tethash("info " + quote(dir / "nothere.msh"));
    EXPECT_EQ(r.status, 2);
    EXPECT_NE(r.err.find("nothere.msh"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("no such file"), std::string::npos) << r.err;
    write_text(dir / "mesh.xyz", "1 2 3\n");
    r = run_tethash("info " + quote(dir / "mesh.xyz"));
    EXPECT_EQ(r.status, 2);
    EXPECT_NE(r.err.find("unknown mesh format"), std::string::npos) << r.err;
    r = run_tethash("info");
    EXPECT_EQ(r.status, 2);
    r = run_tethash("info --no-such-option x.msh");
    EXPECT_EQ(r.status, 2);
}

TEST(CliInfo, IndexPastTheEndExitsTwoNamingTheFile)
{
    const auto dir = temp_dir();
    std::string text = kProblemMesh;
    text.replace(text.find("1 2 5 6 2"), 9, "1 2 5 60 2");
    write_text(dir / "bad.mesh", text);
    const RunResult r = run_tethash("info " + quote(dir / "bad.mesh"));
    EXPECT_EQ(r.status, 2);
    EXPECT_NE(r.err.find("bad.mesh"), std::string::npos) << r.err;
}

// Counts and problems of the real meshes, as given in ../shared/meshes/SOURCES.md.
struct SharedMeshCase {
    const char* file;
    long vertices, tets, inverted, unreferenced;
};

class CliInfoShared : public ::testing::TestWithParam<SharedMeshCase> {};

TEST_P(CliInfoShared, CountsMatchSources)
{
    const SharedMeshCase c = GetParam();
    const auto path = shared_mesh(c.file);
    if (!path) GTEST_SKIP() << "../shared/meshes/" << c.file << " not present";
    const RunResult r = run_tethash("info --json " + quote(*path));
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_EQ(json_int(r.out, "vertices"), c.vertices);
    EXPECT_EQ(json_int(r.out, "tets"), c.tets);
    EXPECT_EQ(json_int(r.out, "objects"), 1);
    EXPECT_EQ(json_int(r.out, "inverted_tets"), c.inverted);
    EXPECT_EQ(json_int(r.out, "degenerate_tets"), 0);
    EXPECT_EQ(json_int(r.out, "unreferenced_vertices"), c.unreferenced);
    EXPECT_EQ(json_int(r.out, "non_manifold_faces"), 0);
}

INSTANTIATE_TEST_SUITE_P(RealMeshes, CliInfoShared,
                         ::testing::Values(SharedMeshCase{"octopus-low.mesh", 452, 1140, 0, 0},
                                           SharedMeshCase{"armadillo_4k.node", 1180, 3717, 0, 0},
                                           SharedMeshCase{"screw.msh", 1732, 6059, 0, 0},
                                           SharedMeshCase{"P1.msh", 1585, 6414, 8, 0},
                                           SharedMeshCase{"raptorTetra_8418.vtu", 2996, 8418, 0, 3},
                                           SharedMeshCase{"32770_octocat.msh", 6133, 21426, 0, 0},
                                           SharedMeshCase{"hand.mesh", 7234, 29998, 0, 0},
                                           SharedMeshCase{"mat100x100t40.msh", 20000, 58806, 0, 0},
                                           SharedMeshCase{"quintupleTorus.veg", 15789, 71427, 0, 0}),
                         [](const auto& info) {
                             std::string n = info.param.file;
                             for (char& ch : n)
                                 if (!std::isalnum(static_cast<unsigned char>(ch))) ch = '_';
                             return n;
                         });
