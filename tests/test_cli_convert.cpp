// tethash convert IN OUT [--reorient]: conversions by extension, counts printed, exit status 2 on bad input.
#include "io_formats_support.hpp"

using namespace tethash;
using namespace tethash::test;

TEST(CliConvert, ConvertsBetweenFormatsAndPrintsCounts)
{
    const auto dir = temp_dir();
    const auto in = data_file("gmsh/two_tets_41.msh");
    const TetMesh original = io::read_mesh(in.string());
    for (const char* name : {"out.mesh", "out.node", "out.msh"}) {
        const RunResult r = run_tethash("convert " + q(in) + " " + q(dir / name));
        ASSERT_EQ(r.status, 0) << name << r.out << r.err;
        EXPECT_NE(r.out.find("5 vertices, 2 tets (2 non-tet cells skipped)"), std::string::npos) << r.out;
        EXPECT_NE(r.out.find("wrote " + (dir / name).string()), std::string::npos) << r.out;
        const TetMesh back = io::read_mesh((dir / name).string());
        expect_same_geometry(back, original, name);
        EXPECT_EQ(back.tet_label, original.tet_label) << name;
    }
    EXPECT_TRUE(std::filesystem::exists(dir / "out.ele"));
}

TEST(CliConvert, ChainThroughEveryWritableFormatIsExact)
{
    const auto dir = temp_dir();
    const TetMesh ref = grid_mesh(2, 3, 2);
    io::write_mesh((dir / "0.msh").string(), ref);
    std::string prev = (dir / "0.msh").string();
    int step = 1;
    for (const char* ext : {".mesh", ".node", ".msh", ".mesh"}) {
        const std::string next = (dir / (std::to_string(step++) + ext)).string();
        const RunResult r = run_tethash("convert '" + prev + "' '" + next + "'");
        ASSERT_EQ(r.status, 0) << r.out << r.err;
        prev = next;
    }
    const TetMesh back = io::read_mesh(prev);
    expect_same_geometry(back, ref, "chain");
    EXPECT_EQ(back.tet_label, ref.tet_label);
}

TEST(CliConvert, ReadsVegaAndTetgenInputs)
{
    const auto dir = temp_dir();
    for (const char* in : {"vega/two_tets.veg", "tetgen/two_tets.ele", "medit/two_tets.mesh", "gmsh/two_tets_22.msh"}) {
        const RunResult r = run_tethash("convert " + q(data_file(in)) + " " + q(dir / "o.msh"));
        ASSERT_EQ(r.status, 0) << in << r.out << r.err;
        EXPECT_NE(r.out.find("5 vertices, 2 tets"), std::string::npos) << r.out;
        expect_same_geometry(io::read_mesh((dir / "o.msh").string()), two_tets(), in);
    }
}

TEST(CliConvert, VtuOutput)
{
    const auto dir = temp_dir();
    const TetMesh ref = grid_mesh(2, 2, 2);
    io::write_mesh((dir / "in.msh").string(), ref);
    const RunResult r = run_tethash("convert " + q(dir / "in.msh") + " " + q(dir / "out.vtu"));
    ASSERT_EQ(r.status, 0) << r.out << r.err;
    auto py = python_with("meshio numpy");
    if (py) {
        write_reference(dir / "ref.txt", ref);
        const RunResult c =
            run_python(*py, dir, python_check_with_meshio("-"), q(dir / "ref.txt") + " " + q(dir / "out.vtu"));
        EXPECT_EQ(c.status, 0) << c.out << c.err;
    } else {
        expect_same_geometry(io::read_mesh((dir / "out.vtu").string()), ref, "vtu");
    }
}

TEST(CliConvert, ReorientFlipsInvertedTets)
{
    const auto p = shared_mesh("P1.msh");
    if (!p) GTEST_SKIP() << "shared mesh absent";
    const auto dir = temp_dir();
    const RunResult keep = run_tethash("convert " + q(*p) + " " + q(dir / "keep.mesh"));
    ASSERT_EQ(keep.status, 0) << keep.err;
    EXPECT_NE(keep.out.find("1585 vertices, 6414 tets"), std::string::npos) << keep.out;
    EXPECT_NE(keep.out.find("8 inverted tets kept"), std::string::npos) << keep.out;
    EXPECT_EQ(validate(io::read_mesh((dir / "keep.mesh").string())).inverted_tets, 8);

    const RunResult fix = run_tethash("convert " + q(*p) + " " + q(dir / "fixed.mesh") + " --reorient");
    ASSERT_EQ(fix.status, 0) << fix.err;
    EXPECT_NE(fix.out.find("reoriented 8 inverted tets"), std::string::npos) << fix.out;
    EXPECT_EQ(validate(io::read_mesh((dir / "fixed.mesh").string())).inverted_tets, 0);
}

TEST(CliConvert, BadInputExitsTwoWithTheMessage)
{
    const auto dir = temp_dir();
    const auto good = data_file("gmsh/two_tets_41.msh");
    {
        const RunResult r = run_tethash("convert " + q(dir / "missing.msh") + " " + q(dir / "o.msh"));
        expect_refused(r, {(dir / "missing.msh").string() + ": no such file"});
    }
    {
        write_text(dir / "x.xyz", "1 2 3\n");
        const RunResult r = run_tethash("convert " + q(dir / "x.xyz") + " " + q(dir / "o.msh"));
        expect_refused(r, {"unknown mesh format '.xyz'"});
    }
    {
        // Broken files of each format: the message names the file and line.
        struct Bad {
            const char* name;
            const char* text;
            int line;
            const char* what;
        };
        for (const Bad& b :
             {Bad{"b.msh", "$MeshFormat\n9.9 0 8\n$EndMeshFormat\n", 2, "expected MSH version 2.2 or 4.1"},
              Bad{"b.mesh", "MeshVersionFormatted 1\nDimension 3\nVertices\n1\n0 nan 0 0\n", 5, "finite y coordinate"},
              Bad{"b.veg", "*VERTICES\n1 3 0 0\n1 0 0 0\n*ELEMENTS\nTET\n1 4 0\n1 1 1 1 2\n", 7,
                  "vertex index 2 is past the end"},
              Bad{"b.node", "1 3 0 0\n0 0 0\n", 2, "z coordinate of node 0, found end of file"}}) {
            write_text(dir / b.name, b.text);
            if (std::string(b.name) == "b.node") write_text(dir / "b.ele", "0 4 0\n");
            const RunResult r = run_tethash("convert " + q(dir / b.name) + " " + q(dir / "o.msh"));
            EXPECT_EQ(r.status, 2) << b.name;
            EXPECT_NE(r.err.find(at_line(dir / b.name, b.line)), std::string::npos) << b.name << ": " << r.err;
            EXPECT_NE(r.err.find(b.what), std::string::npos) << b.name << ": " << r.err;
        }
    }
    {
        const RunResult r = run_tethash("convert " + q(good) + " " + q(dir / "o.xyz"));
        expect_refused(r, {"unknown output format '.xyz'"});
    }
    {
        const RunResult r = run_tethash("convert " + q(good) + " " + q(dir / "no" / "such" / "o.msh"));
        expect_refused(r, {"does not exist"});
    }
    {
        const RunResult r = run_tethash("convert " + q(good));
        EXPECT_EQ(r.status, 2) << r.err;
    }
}

TEST(CliConvert, FailedConversionLeavesTheExistingOutput)
{
    const auto dir = temp_dir();
    const RunResult ok = run_tethash("convert " + q(data_file("gmsh/two_tets_41.msh")) + " " + q(dir / "o.msh"));
    ASSERT_EQ(ok.status, 0) << ok.err;
    const std::string before = read_text(dir / "o.msh");
    write_text(dir / "bad.msh", "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Nodes\n1 1 1 1\n3 1 0 1\n1\n");
    const RunResult bad = run_tethash("convert " + q(dir / "bad.msh") + " " + q(dir / "o.msh"));
    EXPECT_EQ(bad.status, 2);
    EXPECT_EQ(read_text(dir / "o.msh"), before);
}
