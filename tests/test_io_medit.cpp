// Medit .mesh reader and writer: hand-made file with skipped blocks, round trip, meshio interop both
// ways, bad input, the shared Medit meshes.
#include "io_formats_support.hpp"

#include "tethash/io/medit.hpp"

using namespace tethash;
using namespace tethash::test;

namespace {

const HandMadeFile
    good("MeshVersionFormatted 2\nDimension 3\nVertices\n5\n0 0 0 0\n1 0 0 0\n0 1 0 0\n0 0 1 0\n1 1 1 0\n"
         "Tetrahedra\n2\n1 2 3 4 1\n2 3 4 5 1\nEnd\n");

} // namespace

TEST(MeditRead, HandMadeWithRefsAndSkippedBlocks)
{
    io::ReadNotes notes;
    const TetMesh m = read_two_tets_file("medit/two_tets.mesh", &notes);
    EXPECT_EQ(m.tet_label, (std::vector<Index>{7, -2}));
    EXPECT_EQ(m.vertex_label, (std::vector<Index>{1, 2, 0, 3, 4}));
    EXPECT_EQ(notes.skipped_cells, 3); // 1 edge + 2 triangles
}

TEST(MeditWrite, RoundTripExact)
{
    const auto dir = temp_dir();
    TetMesh m = grid_mesh(3, 2, 2);
    round_trip(m, dir, "g.mesh", "g.mesh", "medit round trip");
}

TEST(MeditMeshio, WeReadWhatMeshioWritesAndViceVersa)
{
    TETHASH_SKIP_WITHOUT_PYTHON(py, "meshio numpy");
    const auto dir = temp_dir();
    const TetMesh ref = grid_mesh(3, 2, 2);
    const RunResult w = meshio_writes(py, dir, ref, R"PY(
tri = np.array([[0, 1, 2], [1, 2, 3]])
m = meshio.Mesh(pts, [("triangle", tri), ("tetra", tets)], cell_data={"medit:ref": [np.array([5, 6]), labels]})
meshio.write(sys.argv[2], m, file_format="medit")
)PY",
                                      "mio.mesh");
    ASSERT_EQ(w.status, 0) << w.out << w.err;
    io::ReadNotes notes;
    const TetMesh m = io::read_mesh((dir / "mio.mesh").string(), &notes);
    expect_same_geometry(m, ref, "meshio medit");
    EXPECT_EQ(m.tet_label, ref.tet_label);
    EXPECT_EQ(notes.skipped_cells, 2);

    io::write_mesh((dir / "ours.mesh").string(), ref);
    expect_meshio_reads(py, dir, "medit:ref", {"ours.mesh"});
}

TEST(MeditErrors, VersionAndDimension)
{
    const auto dir = temp_dir();
    expect_read_error(good.edited(dir, "MeshVersionFormatted 2", "MeshVersionFormatted 7", "v.mesh"),
                      {at_line(dir / "v.mesh", 1), "expected MeshVersionFormatted 1, 2, 3 or 4, found version 7"});
    expect_read_error(good.edited(dir, "Dimension 3", "Dimension 2", "d.mesh"),
                      {at_line(dir / "d.mesh", 2), "expected Dimension 3, found Dimension 2"});
    expect_read_error(good.edited(dir, "MeshVersionFormatted 2\n", "", "nov.mesh"),
                      {at_line(dir / "nov.mesh", 1), "expected MeshVersionFormatted, found 'Dimension'"});
}

TEST(MeditErrors, TruncatedAndWrongCounts)
{
    const auto dir = temp_dir();
    const auto cut = good.cut(dir, "2 3 4 5", 0, "cut.mesh");
    expect_read_error(cut, {cut.string() + ":", "vertex 1 of tetrahedron 2", "found end of file"});
    // The Vertices count is 6 but there are 5 vertices: "Tetrahedra" is read as a coordinate.
    const auto p = good.edited(dir, "Vertices\n5\n", "Vertices\n6\n", "count.mesh");
    expect_read_error(p, {at_line(p, 10), "x coordinate of vertex 6", "found 'Tetrahedra'"});
}

TEST(MeditErrors, IndexPastTheEndNanGarbage)
{
    const auto dir = temp_dir();
    expect_read_error(
        good.edited(dir, "2 3 4 5 1", "2 3 4 6 1", "i.mesh"),
        {at_line(dir / "i.mesh", 13), "tetrahedron 2: vertex index 6 is past the end (Vertices has 1..5)"});
    expect_read_error(good.edited(dir, "2 3 4 5 1", "2 3 0 5 1", "z.mesh"),
                      {at_line(dir / "z.mesh", 13), "tetrahedron 2: vertex index 0"});
    expect_read_error(good.edited(dir, "0 0 1 0\n", "0 0 NaN 0\n", "n.mesh"),
                      {at_line(dir / "n.mesh", 8), "finite z coordinate of vertex 4", "found 'NaN'"});
    expect_read_error(good.edited(dir, "Tetrahedra\n2\n", "Tetrahedra\ntwo\n", "g.mesh"),
                      {at_line(dir / "g.mesh", 11), "the number of tetrahedra (an integer)", "found 'two'"});
    expect_read_error(good.edited(dir, "Tetrahedra\n2\n1 2 3 4 1\n2 3 4 5 1\n", "", "not.mesh"),
                      {(dir / "not.mesh").string() + ": no Tetrahedra block"});
}

TEST(MeditShared, ReadsOctopusAndHand)
{
    expect_shared_meshes({{"octopus-low.mesh", 452, 1140, 0, 898}, {"hand.mesh", 7234, 29998, 0, 9556}});
}
