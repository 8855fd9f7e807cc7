// End-to-end tests of `tethash generate` and `tethash tetrahedralize`.
#include "support.hpp"

#include "tethash/io/mesh_io.hpp"
#include "tethash/io/surface.hpp"
#include "tethash/mesh.hpp"

using namespace tethash;
using tethash::test::quote;
using tethash::test::run_tethash;
using tethash::test::temp_dir;

TEST(CliGenerate, ListsShapes)
{
    const auto r = run_tethash("generate --list");
    EXPECT_EQ(r.status, 0) << r.err;
    for (const char* s : {"box", "bar", "sphere", "torus", "cylinder", "capsule"})
        EXPECT_NE(r.out.find(s), std::string::npos) << s;
}

TEST(CliGenerate, WritesAValidMeshAndSaysWhatItMade)
{
    const auto out = temp_dir() / "torus.msh";
    const auto r = run_tethash("generate torus --resolution 12 -o " + quote(out));
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_NE(r.out.find("tets"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("dihedral"), std::string::npos) << r.out;
    const TetMesh m = io::read_mesh(out.string());
    EXPECT_GT(m.num_tets(), 100);
    EXPECT_NE(r.out.find(std::to_string(m.num_tets()) + " tets"), std::string::npos) << r.out;
    const ValidationReport v = validate(m);
    EXPECT_EQ(v.inverted_tets, 0);
    EXPECT_EQ(v.unreferenced_vertices, 0);
}

TEST(CliGenerate, SameCommandSameFile)
{
    const auto dir = temp_dir();
    for (const char* name : {"a.msh", "b.msh"})
        ASSERT_EQ(run_tethash("generate blob -r 10 -o " + quote(dir / name)).status, 0);
    EXPECT_EQ(tethash::test::read_text(dir / "a.msh"), tethash::test::read_text(dir / "b.msh"));
}

TEST(CliGenerate, SizeScaleAndNoSnap)
{
    const auto dir = temp_dir();
    ASSERT_EQ(run_tethash("generate box -r 6 --size 1 2 3 -o " + quote(dir / "s.msh")).status, 0);
    const auto [lo, hi] = bounding_box(io::read_mesh((dir / "s.msh").string()).positions);
    EXPECT_NEAR(hi.z() - lo.z(), 3.0, 1e-9);
    EXPECT_NEAR(hi.y() - lo.y(), 2.0, 1e-9);
    ASSERT_EQ(run_tethash("generate bar -r 8 --scale 2 --no-snap -o " + quote(dir / "b.msh")).status, 0);
    const auto [blo, bhi] = bounding_box(io::read_mesh((dir / "b.msh").string()).positions);
    EXPECT_GT(bhi.x() - blo.x(), 8.0); // unsnapped: the lattice pokes out of the 8-long bar
}

TEST(CliGenerate, BadInputExitsTwoWithAMessage)
{
    const auto dir = temp_dir();
    const std::string out = quote(dir / "x.msh");
    auto r = run_tethash("generate pyramid -o " + out);
    expect_refused(r, {"unknown shape 'pyramid'"});
    r = run_tethash("generate box --resolution 0 -o " + out);
    expect_refused(r, {"--resolution 0"});
    r = run_tethash("generate box --scale -2 -o " + out);
    expect_refused(r, {"--scale"});
    r = run_tethash("generate box --size 1 0 1 -o " + out);
    expect_refused(r, {"--size"});
    r = run_tethash("generate box");
    expect_refused(r, {"-o"});
    r = run_tethash("generate box -o " + quote(dir / "x.unknownext"));
    expect_refused(r, {"x.unknownext"});
    EXPECT_FALSE(std::filesystem::exists(dir / "x.msh"));
}

TEST(CliTetrahedralize, SurfaceFromGenerateBackToTets)
{
    if (!io::have_assimp()) GTEST_SKIP() << "built without assimp";
    const auto dir = temp_dir();
    ASSERT_EQ(run_tethash("generate sphere -r 12 -o " + quote(dir / "sphere.obj")).status, 0);
    const auto r = run_tethash("tetrahedralize " + quote(dir / "sphere.obj") + " -r 12 -o " + quote(dir / "t.msh"));
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_NE(r.out.find("tets"), std::string::npos) << r.out;
    const TetMesh m = io::read_mesh((dir / "t.msh").string());
    const double v = volume_stats(m.positions, m.tets).total;
    EXPECT_NEAR(v, 4.0 / 3.0 * 3.14159265 * 0.125, 0.05 * 0.5236);
    EXPECT_EQ(validate(m).inverted_tets, 0);
}

TEST(CliTetrahedralize, BadInputExitsTwoWithAMessage)
{
    const auto dir = temp_dir();
    auto r = run_tethash("tetrahedralize " + quote(dir / "missing.obj") + " -o " + quote(dir / "t.msh"));
    expect_refused(r, {"missing.obj"});
    if (!io::have_assimp()) return;
    // A single open triangle encloses nothing.
    tethash::test::write_text(dir / "open.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0.5\nf 1 2 3\n");
    r = run_tethash("tetrahedralize " + quote(dir / "open.obj") + " -o " + quote(dir / "t.msh"));
    expect_refused(r, {"open.obj", "nothing is inside"});
    r = run_tethash("tetrahedralize " + quote(dir / "open.obj") + " -r 0 -o " + quote(dir / "t.msh"));
    expect_refused(r, {"--resolution 0"});
    EXPECT_FALSE(std::filesystem::exists(dir / "t.msh"));
}
