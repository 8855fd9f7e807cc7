// Answers users can trust and use: a file without 4-node tets is an error (or linearized on request), collapsed
// tets are skipped with a note, contacts name their objects and each side's file ids (CSV) or come as a VTU,
// simulation frames keep their objects, tetrahedralize and info report connected components, and the boundary
// .obj is one surface for meshio.
#include "cli_support.hpp"
#include "core_scenes.hpp"
#include "support.hpp"
#include "tethash/io/mesh_io.hpp"
#include "tethash/oracle.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <sstream>
#include <string>
#include <vector>

using namespace tethash;
using namespace tethash::test;
namespace fs = std::filesystem;

namespace {

const fs::path kBox = fs::path(TETHASH_SOURCE_DIR) / "meshes" / "box.vtu";

/// One quadratic tet (corners 0..3, mid-edge nodes 4..9) as an ASCII .vtu.
std::string tet10_vtu()
{
    return R"(<?xml version="1.0"?>
<VTKFile type="UnstructuredGrid" version="1.0" byte_order="LittleEndian">
<UnstructuredGrid><Piece NumberOfPoints="10" NumberOfCells="1">
<Points><DataArray type="Float64" NumberOfComponents="3" format="ascii">
0 0 0  1 0 0  0 1 0  0 0 1  0.5 0 0  0.5 0.5 0  0 0.5 0  0 0 0.5  0.5 0 0.5  0 0.5 0.5
</DataArray></Points>
<Cells>
<DataArray type="Int64" Name="connectivity" format="ascii">0 1 2 3 4 5 6 7 8 9</DataArray>
<DataArray type="Int64" Name="offsets" format="ascii">10</DataArray>
<DataArray type="UInt8" Name="types" format="ascii">24</DataArray>
</Cells></Piece></UnstructuredGrid></VTKFile>
)";
}

/// The same quadratic tet as a Gmsh 2.2 file (element type 11, node tags from 101).
std::string tet10_msh()
{
    return "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n10\n"
           "101 0 0 0\n102 1 0 0\n103 0 1 0\n104 0 0 1\n105 0.5 0 0\n106 0.5 0.5 0\n107 0 0.5 0\n108 0 0 0.5\n"
           "109 0.5 0 0.5\n110 0 0.5 0.5\n$EndNodes\n$Elements\n1\n"
           "7 11 2 1 1 101 102 103 104 105 106 107 108 109 110\n$EndElements\n";
}

/// Two triangles and no tet, as an ASCII .vtu.
std::string surface_vtu()
{
    return R"(<?xml version="1.0"?>
<VTKFile type="UnstructuredGrid" version="1.0" byte_order="LittleEndian">
<UnstructuredGrid><Piece NumberOfPoints="4" NumberOfCells="2">
<Points><DataArray type="Float64" NumberOfComponents="3" format="ascii">0 0 0 1 0 0 0 1 0 1 1 0</DataArray></Points>
<Cells>
<DataArray type="Int64" Name="connectivity" format="ascii">0 1 2 1 3 2</DataArray>
<DataArray type="Int64" Name="offsets" format="ascii">3 6</DataArray>
<DataArray type="UInt8" Name="types" format="ascii">5 5</DataArray>
</Cells></Piece></UnstructuredGrid></VTKFile>
)";
}

} // namespace

TEST(CliAnswers, AFileWithoutLinearTetsIsAnErrorNamingWhatItHeld)
{
    const auto dir = temp_dir();
    write_text(dir / "quadratic.vtu", tet10_vtu());
    write_text(dir / "quadratic.msh", tet10_msh());
    write_text(dir / "surface.vtu", surface_vtu());
    for (const std::string cmd : {"info", "detect", "convert"})
        for (const char* f : {"quadratic.vtu", "quadratic.msh", "surface.vtu"}) {
            const std::string args =
                cmd + " " + quote(dir / f) + (cmd == "convert" ? " -o " + quote(dir / (std::string(f) + ".mesh")) : "");
            const auto r = run_tethash(args);
            EXPECT_EQ(r.status, 2) << args << "\n" << r.out << r.err;
            EXPECT_NE(r.err.find(f), std::string::npos) << r.err;
            EXPECT_NE(r.err.find("4-node tets"), std::string::npos) << r.err;
            const bool quadratic = std::string(f).rfind("quadratic", 0) == 0;
            EXPECT_EQ(r.err.find("--linearize") != std::string::npos, quadratic) << r.err;
            EXPECT_FALSE(fs::exists(dir / (std::string(f) + ".mesh")));
        }
    const auto vtu = run_tethash("info " + quote(dir / "quadratic.vtu"));
    EXPECT_NE(vtu.err.find("1 cells of type 24 (quadratic tetra)"), std::string::npos) << vtu.err;
    const auto tri = run_tethash("info " + quote(dir / "surface.vtu"));
    EXPECT_NE(tri.err.find("2 cells of type 5"), std::string::npos) << tri.err;
}

TEST(CliAnswers, LinearizeKeepsTheCornersOfQuadraticTets)
{
    const auto dir = temp_dir();
    write_text(dir / "quadratic.vtu", tet10_vtu());
    write_text(dir / "quadratic.msh", tet10_msh());
    for (const char* f : {"quadratic.vtu", "quadratic.msh"}) {
        const auto r =
            run_tethash("convert --linearize " + quote(dir / f) + " -o " + quote(dir / (std::string(f) + ".vtk")));
        ASSERT_EQ(r.status, 0) << r.err;
        const TetMesh m = io::read_mesh((dir / (std::string(f) + ".vtk")).string());
        ASSERT_EQ(m.num_tets(), 1);
        EXPECT_EQ(m.num_vertices(), 4); // the mid-edge nodes are dropped
        EXPECT_DOUBLE_EQ(std::abs(signed_volume(m.positions, {m.tets(0, 0), m.tets(0, 1), m.tets(0, 2), m.tets(0, 3)})),
                         1.0 / 6.0);
        const auto info = run_tethash("info --linearize " + quote(dir / f));
        EXPECT_EQ(info.status, 0) << info.err;
        const auto det = run_tethash("detect --linearize " + quote(dir / f));
        EXPECT_EQ(det.status, 0) << det.err;
        EXPECT_NE(det.out.find("contacts: 0"), std::string::npos) << det.out; // no mid-edge node on an edge
    }
}

TEST(CliAnswers, CollapsedTetsAreSkippedWithANoteAndTheRestIsChecked)
{
    const auto dir = temp_dir();
    Scene a = lattice_object(3, 3, 3, 0.25, Eigen::Vector3d(0, 0, 0));
    const Scene b = lattice_object(3, 3, 3, 0.25, Eigen::Vector3d(0.125, 0.125, 0.3));
    a.tets(5, 3) = a.tets(5, 1); // a collapsed tet, as converters write them
    write_text(dir / "a.mesh", medit_text(a));
    write_text(dir / "b.mesh", medit_text(b));
    const auto r = run_tethash("detect " + quote(dir / "a.mesh") + " " + quote(dir / "b.mesh") + " --contacts " +
                               quote(dir / "c.csv"));
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_NE(r.out.find("1 tets with a repeated vertex"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("1 degenerate tets"), std::string::npos) << r.out;
    Scene s = a;
    append_object(s, b);
    const auto want = brute_force_contacts(s.positions, s.tets, s.vertex_object, s.tet_object);
    ASSERT_FALSE(want.empty());
    EXPECT_EQ(csv_rows(read_text(dir / "c.csv")).size(), want.size() + 1);
    const auto info = run_tethash("info " + quote(dir / "a.mesh"));
    EXPECT_NE(info.out.find("repeated vertex"), std::string::npos) << info.out; // still a problem for info
}

TEST(CliAnswers, ContactsCsvNamesObjectsAndEachSidesFileAndId)
{
    const auto dir = temp_dir();
    const Scene a = lattice_object(3, 3, 3, 0.25, Eigen::Vector3d(0, 0, 0));
    const Scene b = lattice_object(3, 3, 3, 0.25, Eigen::Vector3d(0.125, 0.125, 0.3));
    write_text(dir / "a.mesh", medit_text(a)); // Medit: 1-based
    ASSERT_EQ(run_tethash("convert " + quote(dir / "a.mesh") + " -o " + quote(dir / "b0.vtu")).status, 0);
    write_text(dir / "b.mesh", medit_text(b));
    ASSERT_EQ(run_tethash("convert " + quote(dir / "b.mesh") + " -o " + quote(dir / "b.vtu")).status,
              0); // VTK: 0-based
    const auto r = run_tethash("detect " + quote(dir / "a.mesh") + " " + quote(dir / "b.vtu") + " --contacts " +
                               quote(dir / "c.csv"));
    ASSERT_EQ(r.status, 0) << r.err;
    const std::string text = read_text(dir / "c.csv");
    EXPECT_EQ(text.rfind("# ", 0), 0u); // a header comment says which id is which
    EXPECT_NE(text.find("1-based in Medit"), std::string::npos);
    const auto rows = csv_rows(text);
    ASSERT_GT(rows.size(), 1u);
    EXPECT_EQ(rows[0], (std::vector<std::string>{"vertex", "tet", "vertex_object", "tet_object", "vertex_file",
                                                 "vertex_in_file", "tet_file", "tet_in_file", "b0", "b1", "b2", "b3"}));
    const long na = a.positions.rows(), ma = a.tets.rows();
    bool both_ways[2] = {false, false};
    for (std::size_t i = 1; i < rows.size(); ++i) {
        const auto& c = rows[i];
        const long v = std::stol(c[0]), t = std::stol(c[1]);
        const long vf = std::stol(c[4]), vl = std::stol(c[5]), tf = std::stol(c[6]), tl = std::stol(c[7]);
        EXPECT_EQ(vf, v < na ? 0 : 1);
        EXPECT_EQ(tf, t < ma ? 0 : 1);
        EXPECT_EQ(std::stol(c[2]), vf); // each file one object
        EXPECT_EQ(std::stol(c[3]), tf);
        EXPECT_EQ(vl, vf == 0 ? v + 1 : v - na); // Medit 1-based, VTK 0-based
        EXPECT_EQ(tl, tf == 0 ? t + 1 : t - ma);
        both_ways[vf] = true;
    }
    EXPECT_TRUE(both_ways[0] && both_ways[1]);
}

TEST(CliAnswers, ContactsCsvGivesGmshTags)
{
    const auto dir = temp_dir();
    write_text(dir / "q.msh", tet10_msh());
    // Two copies of one tet, the second shifted so that its corner 101 lies inside the first.
    ASSERT_EQ(run_tethash("convert --linearize " + quote(dir / "q.msh") + " -o " + quote(dir / "q.vtu")).status, 0);
    TetMesh m = io::read_mesh((dir / "q.vtu").string());
    m.positions.rowwise() += Eigen::RowVector3d(0.1, 0.1, 0.1);
    io::write_mesh((dir / "shifted.vtu").string(), m);
    const auto r = run_tethash("detect --linearize " + quote(dir / "shifted.vtu") + " " + quote(dir / "q.msh") +
                               " --contacts " + quote(dir / "c.csv"));
    ASSERT_EQ(r.status, 0) << r.err;
    const auto rows = csv_rows(read_text(dir / "c.csv"));
    ASSERT_EQ(rows.size(), 2u) << read_text(dir / "c.csv");
    EXPECT_EQ(rows[1][5], "0"); // the vertex: point 0 of shifted.vtu
    EXPECT_EQ(rows[1][6], "1");
    EXPECT_EQ(rows[1][7], "7"); // the tet: element tag 7 of q.msh
}

TEST(CliAnswers, ContactsVtuHoldsTheMeshesWithContactFields)
{
    const auto dir = temp_dir();
    const Scene a = lattice_object(3, 3, 3, 0.25, Eigen::Vector3d(0, 0, 0));
    const Scene b = lattice_object(3, 3, 3, 0.25, Eigen::Vector3d(0.125, 0.125, 0.3));
    write_text(dir / "a.mesh", medit_text(a));
    write_text(dir / "b.mesh", medit_text(b));
    const auto r = run_tethash("detect " + quote(dir / "a.mesh") + " " + quote(dir / "b.mesh") + " --contacts " +
                               quote(dir / "c.vtu"));
    ASSERT_EQ(r.status, 0) << r.err;
    const std::string xml = read_text(dir / "c.vtu");
    EXPECT_EQ(xml.rfind("<?xml", 0), 0u) << "not a VTU";
    for (const char* name : {"\"contact\"", "\"penetration_depth\"", "\"contact_tet\"", "\"object\""})
        EXPECT_NE(xml.find(name), std::string::npos) << name;
    const TetMesh m = io::read_mesh((dir / "c.vtu").string());
    EXPECT_EQ(m.num_tets(), a.tets.rows() + b.tets.rows());
    EXPECT_EQ(m.num_objects(), 2);
    // An unknown extension is an error before any work.
    const auto bad = run_tethash("detect " + quote(dir / "a.mesh") + " --contacts " + quote(dir / "c.txt"));
    expect_refused(bad, {"--contacts"});
    EXPECT_EQ(bad.out, "");
    EXPECT_FALSE(fs::exists(dir / "c.txt"));
}

TEST(CliAnswers, DetectReadsTheObjectsOfASimulationFrame)
{
    const auto dir = temp_dir();
    const auto sim = run_tethash("simulate --steps 2 -o " + quote(dir / "sim"));
    ASSERT_EQ(sim.status, 0) << sim.err;
    const fs::path frame = dir / "sim" / "frame_00000.vtu";
    ASSERT_TRUE(fs::exists(frame));
    const Index objects = io::read_mesh(frame.string()).num_objects();
    ASSERT_GT(objects, 1);
    const auto r = run_tethash("detect " + quote(frame));
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_NE(r.out.find("scene: " + std::to_string(objects) + " objects"), std::string::npos) << r.out;
}

TEST(CliAnswers, InfoAndTetrahedralizeCountConnectedComponents)
{
    const auto dir = temp_dir();
    const auto one = run_tethash("info " + quote(kBox));
    EXPECT_NE(one.out.find("connected components 1"), std::string::npos) << one.out;
    const auto two = run_tethash("info " + quote(kBox) + " " + quote(kBox) + " --json");
    EXPECT_NE(two.out.find("\"components\": 2"), std::string::npos) << two.out;
    const fs::path blob = fs::path(TETHASH_SOURCE_DIR) / "meshes" / "surfaces" / "blob.obj";
    const auto t = run_tethash("tetrahedralize " + quote(blob) + " -r 6 -o " + quote(dir / "blob.vtu"));
    if (t.status == 2 && t.err.find("assimp") != std::string::npos) GTEST_SKIP() << "built without assimp";
    ASSERT_EQ(t.status, 0) << t.err;
    EXPECT_NE(t.out.find("components: 1"), std::string::npos) << t.out;
    EXPECT_NE(t.out.find("the surface encloses"), std::string::npos) << t.out;
    // An open surface: a warning.
    std::string obj = read_text(blob);
    obj = obj.substr(0, obj.rfind("\nf ")) + "\n"; // drops the last triangle
    write_text(dir / "open.obj", obj);
    const auto open = run_tethash("tetrahedralize " + quote(dir / "open.obj") + " -r 6 -o " + quote(dir / "open.vtu"));
    EXPECT_NE(open.err.find("the surface is open"), std::string::npos) << open.err;
}

TEST(CliAnswers, BoundaryObjIsOneSurfaceForMeshio)
{
    const auto dir = temp_dir();
    ASSERT_EQ(run_tethash("convert " + quote(kBox) + " -o " + quote(dir / "b.obj")).status, 0);
    const std::string obj = read_text(dir / "b.obj");
    EXPECT_EQ(obj.find("//"), std::string::npos); // no per-corner normal indices
    TETHASH_SKIP_WITHOUT_PYTHON(py, "meshio");
    const auto r = run_shell(py + " -c \"import meshio; m = meshio.read('" + (dir / "b.obj").string() +
                             "'); print(len(m.points), sum(len(c.data) for c in m.cells))\"");
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_EQ(r.out, "302 600\n"); // shared vertices: the 302 boundary vertices of box.vtu, 600 triangles
}
