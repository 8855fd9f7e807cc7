// `tethash info`: counts and problems, JSON for scripts, every shared real mesh, bad input.
#include "cli_support.hpp"
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

/// kProblemMesh written as `name` into a fresh folder; the file's path, quoted for the command line.
std::string problem_mesh(const std::string& name = "problems.mesh")
{
    const auto path = temp_dir() / name;
    write_text(path, kProblemMesh);
    return quote(path);
}

} // namespace

TEST(CliInfo, ReportsProblemsInJson)
{
    const RunResult r = run_tethash("info --json " + problem_mesh());
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
    const RunResult r = run_tethash("info " + problem_mesh());
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_NE(r.out.find("vertices 8"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("1 inverted tets"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("2 unreferenced vertices"), std::string::npos) << r.out;
}

TEST(CliInfo, SeveralFilesAreOneSceneWithObjects)
{
    const std::string mesh = problem_mesh("a.mesh");
    const RunResult r = run_tethash("info --json " + mesh + " " + mesh);
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
    expect_refused(r, {"nothere.msh", "no such file"});
    write_text(dir / "mesh.xyz", "1 2 3\n");
    r = run_tethash("info " + quote(dir / "mesh.xyz"));
    expect_refused(r, {"unknown mesh format"});
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
    expect_refused(r, {"bad.mesh"});
}

TEST(CliInfo, ObjectsFromLabels)
{
    const auto dir = temp_dir();
    write_text(dir / "bodies.msh", kTwoBodiesMsh);
    RunResult r = run_tethash("info --json " + quote(dir / "bodies.msh"));
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_EQ(json_int(r.out, "objects"), 1);
    r = run_tethash("info --json --objects-from-labels " + quote(dir / "bodies.msh"));
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_EQ(json_int(r.out, "objects"), 2);
    EXPECT_NE(r.out.find("2 objects from tet labels"), std::string::npos) << r.out;
    // Two files: objects of the second follow those of the first.
    r = run_tethash("info --json --objects-from-labels " + quote(dir / "bodies.msh") + " " + quote(dir / "bodies.msh"));
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_EQ(json_int(r.out, "objects"), 4);

    // Tets of two labels that share a face: an error naming the file and a vertex, or one object with =join.
    write_text(dir / "glued.msh",
               std::string(kTwoBodiesMsh)
                   .replace(std::string(kTwoBodiesMsh).find("1 4 2 6 60 5 6 7 8"), 18, "1 4 2 6 60 2 3 4 6"));
    r = run_tethash("info --objects-from-labels " + quote(dir / "glued.msh"));
    expect_refused(r, {"glued.msh", "vertex ", "=join"});
    r = run_tethash("info --json --objects-from-labels=join " + quote(dir / "glued.msh"));
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_EQ(json_int(r.out, "objects"), 1);
    EXPECT_NE(r.out.find("3 shared vertices"), std::string::npos) << r.out;
    r = run_tethash("info --objects-from-labels=maybe " + quote(dir / "glued.msh"));
    expect_refused(r, {"--objects-from-labels"});
}

// Counts and problems of the real meshes, as given in ../shared/meshes/SOURCES.md (vertices, tets,
// inverted tets, unreferenced vertices, unique edges, boundary triangles).
struct SharedMeshCase {
    const char* file;
    long vertices, tets, inverted, unreferenced;
    long edges, boundary_faces; ///< "Unique edges" and "Boundary triangles" of SOURCES.md
};

/// Value of "count" inside the "edges" object of info's JSON, or -1.
long json_edge_count(const std::string& json)
{
    std::smatch m;
    if (std::regex_search(json, m, std::regex("\"edges\": \\{\"count\": ([0-9]+)"))) return std::stol(m[1]);
    return -1;
}

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
    EXPECT_EQ(json_edge_count(r.out), c.edges);
    EXPECT_EQ(json_int(r.out, "boundary_faces"), c.boundary_faces);
}

// convert keeps what SOURCES.md counts: the same edges and boundary faces after a round through .vtu.
TEST_P(CliInfoShared, ConvertKeepsEdgesAndBoundary)
{
    const SharedMeshCase c = GetParam();
    const auto path = shared_mesh(c.file);
    if (!path) GTEST_SKIP() << "../shared/meshes/" << c.file << " not present";
    const auto dir = temp_dir();
    const RunResult conv = run_tethash("convert " + quote(*path) + " " + quote(dir / "copy.vtu"));
    ASSERT_EQ(conv.status, 0) << conv.err;
    const RunResult r = run_tethash("info --json " + quote(dir / "copy.vtu"));
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_EQ(json_int(r.out, "vertices"), c.vertices);
    EXPECT_EQ(json_int(r.out, "tets"), c.tets);
    EXPECT_EQ(json_edge_count(r.out), c.edges);
    EXPECT_EQ(json_int(r.out, "boundary_faces"), c.boundary_faces);
    EXPECT_EQ(json_int(r.out, "inverted_tets"), c.inverted);
}

INSTANTIATE_TEST_SUITE_P(RealMeshes, CliInfoShared,
                         ::testing::Values(SharedMeshCase{"octopus-low.mesh", 452, 1140, 0, 0, 2040, 898},
                                           SharedMeshCase{"armadillo_4k.node", 1180, 3717, 0, 0, 5947, 2102},
                                           SharedMeshCase{"screw.msh", 1732, 6059, 0, 0, 9204, 2828},
                                           SharedMeshCase{"P1.msh", 1585, 6414, 8, 0, 8890, 1762},
                                           SharedMeshCase{"raptorTetra_8418.vtu", 2996, 8418, 0, 3, 14284, 5750},
                                           SharedMeshCase{"32770_octocat.msh", 6133, 21426, 0, 0, 31835, 8554},
                                           SharedMeshCase{"hand.mesh", 7234, 29998, 0, 0, 42009, 9556},
                                           SharedMeshCase{"mat100x100t40.msh", 20000, 58806, 0, 0, 98803, 39996},
                                           SharedMeshCase{"quintupleTorus.veg", 15789, 71427, 0, 0, 94675, 14816}),
                         [](const auto& info) {
                             std::string n = info.param.file;
                             for (char& ch : n)
                                 if (!std::isalnum(static_cast<unsigned char>(ch))) ch = '_';
                             return n;
                         });
