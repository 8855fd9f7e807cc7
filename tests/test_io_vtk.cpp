// VTK legacy (.vtk) and VTK XML (.vtu): round trips through our writers and readers, dispatch, bad fields,
// both legacy cell layouts, the shared real .vtu mesh (meshio and the VTK library: test_io_vtk_interop.cpp).
#include "vtk_support.hpp"

#include "tethash/error.hpp"

#include <cmath>
#include <map>

using namespace tethash;
using namespace tethash::test;

// ---- our writers → our readers ------------------------------------------------------------

TEST(IoVtk, VtuRoundTripIsExact)
{
    const auto dir = temp_dir();
    const TetMesh m = grid_mesh();
    io::write_vtu((dir / "m.vtu").string(), m, sample_fields(m));
    io::ReadNotes notes;
    const TetMesh r = io::read_vtu((dir / "m.vtu").string(), &notes);
    expect_same_mesh(m, r, 0, "vtu");
    EXPECT_EQ(notes.skipped_cells, 0);
    EXPECT_EQ(r.tet_object, m.tet_object);
    EXPECT_EQ(r.vertex_object, m.vertex_object);
    EXPECT_EQ(r.tet_label, m.tet_label);
    EXPECT_EQ(r.num_objects(), 2);
}

TEST(IoVtk, LegacyRoundTripBinaryAndAsciiIsExact)
{
    const auto dir = temp_dir();
    const TetMesh m = grid_mesh();
    for (bool binary : {true, false}) {
        const auto path = (dir / (binary ? "b.vtk" : "a.vtk")).string();
        io::write_vtk(path, m, sample_fields(m), binary);
        EXPECT_NE(read_text(path).find(binary ? "\nBINARY\n" : "\nASCII\n"), std::string::npos) << path;
        const TetMesh r = io::read_vtk(path);
        expect_same_mesh(m, r, 0, path);
        EXPECT_EQ(r.tet_object, m.tet_object) << path;
        EXPECT_EQ(r.vertex_object, m.vertex_object) << path;
        EXPECT_EQ(r.tet_label, m.tet_label) << path;
    }
}

TEST(IoVtk, ReadMeshDispatchAndEmptyMesh)
{
    const auto dir = temp_dir();
    TetMesh empty;
    empty.positions.resize(0, 3);
    empty.tets.resize(0, 4);
    io::write_mesh((dir / "e.vtu").string(), empty);
    io::write_mesh((dir / "e.vtk").string(), empty);
    EXPECT_EQ(io::read_mesh((dir / "e.vtu").string()).num_vertices(), 0);
    EXPECT_EQ(io::read_mesh((dir / "e.vtk").string()).num_tets(), 0);
    const TetMesh m = grid_mesh(1, 1, 1);
    io::write_mesh((dir / "m.vtu").string(), m);
    expect_same_mesh(m, io::read_mesh((dir / "m.vtu").string()), 0, "read_mesh .vtu");
}

TEST(IoVtk, WriterRejectsBadFieldsAndLeavesNoFile)
{
    const auto dir = temp_dir();
    const TetMesh m = grid_mesh(1, 1, 1);
    io::Fields f;
    f.point.push_back({"velocity", 3, std::vector<double>(5, 0.0)});
    try {
        io::write_vtu((dir / "m.vtu").string(), m, f);
        FAIL() << "expected an Error";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("'velocity' has 5 values, expected 8 × 3 = 24"), std::string::npos)
            << e.what();
    }
    EXPECT_FALSE(std::filesystem::exists(dir / "m.vtu"));
    io::Fields spaced;
    spaced.cell.push_back({"von mises", 1, std::vector<double>(static_cast<std::size_t>(m.num_tets()), 1.0)});
    EXPECT_THROW(io::write_vtk((dir / "m.vtk").string(), m, spaced), Error);
    EXPECT_NO_THROW(io::write_vtu((dir / "m.vtu").string(), m, spaced)); // XML stores spaces
    // A failed write keeps the previous good file.
    const std::string before = read_text(dir / "m.vtu");
    EXPECT_THROW(io::write_vtu((dir / "m.vtu").string(), m, f), Error);
    EXPECT_EQ(read_text(dir / "m.vtu"), before);
    EXPECT_THROW(io::write_vtu((dir / "no_such_dir" / "m.vtu").string(), m), Error);
}

// ---- hand-made small files: layouts, skipped cells ------------------------------------------

TEST(IoVtk, LegacyClassicAndOffsetsLayoutsSkipOtherCells)
{
    const auto dir = temp_dir();
    const std::string points = "POINTS 5 float\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n1 1 1\n";
    write_text(dir / "v2.vtk", "# vtk DataFile Version 2.0\nsmall\nASCII\nDATASET UNSTRUCTURED_GRID\n" + points +
                                   "CELLS 3 13\n3 0 1 2\n4 0 1 2 3\n3 1 2 4\nCELL_TYPES 3\n5\n10\n5\n"
                                   "CELL_DATA 3\nSCALARS gmsh:physical int 1\nLOOKUP_TABLE default\n7 8 9\n"
                                   "POINT_DATA 5\nVECTORS v double\n0 0 0 1 1 1 2 2 2 3 3 3 4 4 4\n");
    write_text(dir / "v51.vtk", "# vtk DataFile Version 5.1\nsmall\nASCII\nDATASET UNSTRUCTURED_GRID\n" + points +
                                    "METADATA\nINFORMATION 0\n\n"
                                    "CELLS 4 11\nOFFSETS vtktypeint64\n0 4 7 11\nCONNECTIVITY vtktypeint64\n"
                                    "1 2 3 4\n0 1 2\n4 3 2 1\nCELL_TYPES 3\n10 5 10\n");
    io::ReadNotes n2, n51;
    const TetMesh a = io::read_vtk((dir / "v2.vtk").string(), &n2);
    ASSERT_EQ(a.num_tets(), 1);
    EXPECT_EQ(a.tets(0, 3), 3);
    EXPECT_EQ(n2.skipped_cells, 2);
    ASSERT_EQ(a.tet_label.size(), 1u);
    EXPECT_EQ(a.tet_label[0], 8);
    const TetMesh b = io::read_vtk((dir / "v51.vtk").string(), &n51);
    ASSERT_EQ(b.num_tets(), 2);
    EXPECT_EQ(b.tets(1, 0), 4);
    EXPECT_EQ(b.tets(1, 3), 1);
    EXPECT_EQ(n51.skipped_cells, 1);
    ASSERT_FALSE(n51.messages.empty());
    EXPECT_NE(n51.messages[0].find("triangle"), std::string::npos);
}

TEST(IoVtk, SharedRaptorVtu)
{
    const auto p = shared_mesh("raptorTetra_8418.vtu");
    if (!p) GTEST_SKIP() << "shared mesh raptorTetra_8418.vtu is absent";
    io::ReadNotes notes;
    const TetMesh m = io::read_vtu(p->string(), &notes);
    EXPECT_EQ(m.num_vertices(), 2996);
    EXPECT_EQ(m.num_tets(), 8418);
    EXPECT_EQ(notes.skipped_cells, 0);
    const auto [lo, hi] = bounding_box(m.positions);
    EXPECT_NEAR(lo.x(), -2.11393, 1e-5);
    EXPECT_NEAR(hi.y(), 6.97908, 1e-5);
    const ValidationReport rep = validate(m);
    EXPECT_TRUE(rep.ok());
    EXPECT_EQ(rep.unreferenced_vertices, 3);
    EXPECT_EQ(rep.inverted_tets, 0);
}

// ---- meshio interoperability ------------------------------------------------------------------

// The static surfaces a simulation writes beside its frames: triangles with an "object" cell array, read back with
// every data array (read_vtu_contents), and the fields of a tet frame read back per point and per cell.
TEST(IoVtk, SurfaceAndFieldsReadBackWithTheirContents)
{
    const auto dir = temp_dir();
    meshing::SurfaceMesh s;
    s.vertices.resize(4, 3);
    s.vertices << 0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0.5;
    s.triangles.resize(2, 3);
    s.triangles << 0, 1, 2, 0, 2, 3;
    io::write_vtu_surface((dir / "s.vtu").string(), s, {3, -1});
    const io::VtuContents c = io::read_vtu_contents((dir / "s.vtu").string());
    EXPECT_EQ(c.mesh.num_tets(), 0);
    EXPECT_EQ(c.mesh.positions, s.vertices);
    EXPECT_EQ(c.triangles, s.triangles);
    ASSERT_EQ(c.fields.cell.size(), 1u);
    EXPECT_EQ(c.fields.cell[0].name, "object");
    EXPECT_EQ(c.fields.cell[0].values, (std::vector<double>{3, -1}));
    EXPECT_THROW(io::write_vtu_surface((dir / "t.vtu").string(), s, {1}), Error); // one id per triangle
    EXPECT_FALSE(std::filesystem::exists(dir / "t.vtu"));

    TetMesh m;
    m.positions.resize(4, 3);
    m.positions << 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1;
    m.tets.resize(1, 4);
    m.tets << 0, 1, 2, 3;
    io::Fields f;
    f.point.push_back({"heat", 1, {1, 2, 3, 4}});
    f.point.push_back({"velocity", 3, std::vector<double>(12, 0.5)});
    f.cell.push_back({"stress", 1, {7}});
    io::write_vtu((dir / "m.vtu").string(), m, f);
    const io::VtuContents d = io::read_vtu_contents((dir / "m.vtu").string());
    EXPECT_EQ(d.mesh.tets, m.tets);
    EXPECT_EQ(d.triangles.rows(), 0);
    ASSERT_EQ(d.tet_cells, (std::vector<std::int64_t>{0}));
    std::map<std::string, std::vector<double>> got;
    for (const auto* list : {&d.fields.point, &d.fields.cell})
        for (const io::Field& x : *list)
            got[x.name] = x.values;
    EXPECT_EQ(got["heat"], (std::vector<double>{1, 2, 3, 4}));
    EXPECT_EQ(got["velocity"], std::vector<double>(12, 0.5));
    EXPECT_EQ(got["stress"], (std::vector<double>{7}));
}
