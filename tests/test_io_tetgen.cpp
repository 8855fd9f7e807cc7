// TetGen .node/.ele reader and writer: hand-made files (0/1-based, attributes, markers, comments,
// 10-node tets), round trips, meshio interop both ways, bad input, the shared armadillo mesh.
#include "io_formats_support.hpp"

#include "tethash/io/tetgen.hpp"

using namespace tethash;
using namespace tethash::test;

namespace {

/// Writes NAME.node and NAME.ele into `dir`; returns the .node path.
std::filesystem::path write_pair(const std::filesystem::path& dir, const std::string& name, const std::string& node,
                                 const std::string& ele)
{
    write_text(dir / (name + ".node"), node);
    write_text(dir / (name + ".ele"), ele);
    return dir / (name + ".node");
}

const char* k_node0 = "5 3 0 0\n0 0 0 0\n1 1 0 0\n2 0 1 0\n3 0 0 1\n4 1 1 1\n";
const char* k_ele0 = "2 4 0\n0 0 1 2 3\n1 1 2 3 4\n";

} // namespace

TEST(TetgenRead, HandMadeOneBasedWithAttributesMarkersAndComments)
{
    for (const char* which : {"tetgen/two_tets.node", "tetgen/two_tets.ele"}) {
        io::ReadNotes notes;
        const TetMesh m = io::read_mesh(data_file(which).string(), &notes);
        expect_same_geometry(m, two_tets(), which);
        EXPECT_EQ(m.tet_label, (std::vector<Index>{7, -2})) << which;
        EXPECT_EQ(m.vertex_label, (std::vector<Index>{1, 2, 0, 3, 4})) << which;
        EXPECT_EQ(notes.skipped_cells, 0);
    }
}

TEST(TetgenRead, ZeroBased)
{
    const auto dir = temp_dir();
    const auto p = write_pair(dir, "z", k_node0, k_ele0);
    const TetMesh m = io::read_tetgen(p.string());
    expect_same_geometry(m, two_tets(), "zero-based");
    EXPECT_TRUE(m.tet_label.empty());
    EXPECT_TRUE(m.vertex_label.empty());
}

TEST(TetgenRead, ShortHeadersUseTetgenDefaults)
{
    const auto dir = temp_dir();
    // Only the counts: dimension 3, no attributes, no markers, 4 nodes per tet.
    const auto p =
        write_pair(dir, "s", std::string("5\n") + (std::string(k_node0).substr(8)), "2\n0 0 1 2 3\n1 1 2 3 4\n");
    expect_same_geometry(io::read_tetgen(p.string()), two_tets(), "short headers");
}

TEST(TetgenRead, TenNodeTetsUseTheirCornersWithANote)
{
    const auto dir = temp_dir();
    const auto p = write_pair(dir, "q", k_node0, "2 10 0\n0 0 1 2 3 0 1 2 3 4 0\n1 1 2 3 4 1 2 3 4 0 1\n");
    io::ReadNotes notes;
    const TetMesh m = io::read_tetgen(p.string(), &notes);
    expect_same_geometry(m, two_tets(), "10-node");
    ASSERT_EQ(notes.messages.size(), 1u);
    EXPECT_NE(notes.messages[0].find("10-node tets read as 4-node tets"), std::string::npos);
}

TEST(TetgenRead, NonIntegerRegionAttributesAreNotLabels)
{
    const auto dir = temp_dir();
    const auto p = write_pair(dir, "a", k_node0, "2 4 1\n0 0 1 2 3 0.5\n1 1 2 3 4 2\n");
    io::ReadNotes notes;
    const TetMesh m = io::read_tetgen(p.string(), &notes);
    EXPECT_TRUE(m.tet_label.empty());
    ASSERT_EQ(notes.messages.size(), 1u);
    EXPECT_NE(notes.messages[0].find("not integer-valued"), std::string::npos);
}

TEST(TetgenWrite, RoundTripExactWithLabelsAndMarkers)
{
    const auto dir = temp_dir();
    TetMesh m = grid_mesh(3, 2, 2);
    m.vertex_label.resize(static_cast<std::size_t>(m.num_vertices()));
    for (std::size_t v = 0; v < m.vertex_label.size(); ++v)
        m.vertex_label[v] = static_cast<Index>(v % 4);
    // Either name writes both files.
    EXPECT_EQ(round_trip(m, dir, "g.ele", "g.node", "tetgen round trip").vertex_label, m.vertex_label);
}

TEST(TetgenMeshio, WeReadWhatMeshioWritesAndViceVersa)
{
    TETHASH_SKIP_WITHOUT_PYTHON(py, "meshio numpy");
    const auto dir = temp_dir();
    const TetMesh ref = grid_mesh(3, 2, 2);
    const RunResult w = meshio_writes(py, dir, ref, R"PY(
m = meshio.Mesh(pts, [("tetra", tets)], cell_data={"tetgen:ref": [labels]})
meshio.write(sys.argv[2], m, file_format="tetgen")
)PY",
                                      "mio.node");
    ASSERT_EQ(w.status, 0) << w.out << w.err;
    const TetMesh m = io::read_mesh((dir / "mio.ele").string());
    expect_same_geometry(m, ref, "meshio tetgen");
    EXPECT_EQ(m.tet_label, ref.tet_label);

    io::write_mesh((dir / "ours.node").string(), ref);
    expect_meshio_reads(py, dir, "tetgen:ref", {"ours.node"});
}

TEST(TetgenErrors, MissingPartner)
{
    const auto dir = temp_dir();
    write_text(dir / "lonely.node", k_node0);
    expect_read_error(dir / "lonely.node", {(dir / "lonely.ele").string() + ": no such file"});
}

TEST(TetgenErrors, TruncatedAndWrongCounts)
{
    const auto dir = temp_dir();
    {
        const auto p = write_pair(dir, "t1", "5 3 0 0\n0 0 0 0\n1 1 0 0\n2 0 1 0\n", k_ele0);
        expect_read_error(p, {at_line(p, 4), "expected a node index", "found end of file"});
    }
    {
        // The .ele header says 3 tets; there are 2.
        const auto p = write_pair(dir, "t2", k_node0, "3 4 0\n0 0 1 2 3\n1 1 2 3 4\n");
        expect_read_error(p, {(dir / "t2.ele").string() + ":", "expected a tet index", "found end of file"});
    }
    {
        // The .node header says 4 nodes; there are 5.
        const std::string node = std::string("4") + (k_node0 + 1);
        const auto p = write_pair(dir, "t3", node, k_ele0);
        expect_read_error(p, {at_line(p, 6), "expected end of file after 4 nodes, found '4'"});
    }
    {
        const auto p = write_pair(dir, "t4", k_node0, "2 4 0\n0 0 1 2 3\n2 1 2 3 4\n");
        expect_read_error(p, {at_line(dir / "t4.ele", 3), "expected tet index 1", "found 2"});
    }
    {
        const auto p = write_pair(dir, "t5", "5 2 0 0\n", k_ele0);
        expect_read_error(p, {at_line(p, 1), "expected dimension 3, found 2"});
    }
    {
        const auto p = write_pair(dir, "t6", "5 3 0 0\n7 0 0 0\n", k_ele0);
        expect_read_error(p, {at_line(p, 2), "expected the first node index 0 or 1, found 7"});
    }
}

TEST(TetgenErrors, IndexPastTheEnd)
{
    const auto dir = temp_dir();
    const auto p = write_pair(dir, "i", k_node0, "2 4 0\n0 0 1 2 3\n1 1 2 3 5\n");
    expect_read_error(p, {at_line(dir / "i.ele", 3), "tet 1: node index 5 is past the end", "indices 0..4"});
}

TEST(TetgenErrors, NanAndGarbage)
{
    const auto dir = temp_dir();
    {
        const auto p = write_pair(dir, "n", "5 3 0 0\n0 0 0 0\n1 1 nan 0\n2 0 1 0\n3 0 0 1\n4 1 1 1\n", k_ele0);
        expect_read_error(p, {at_line(p, 3), "y coordinate of node 1 (a finite number)", "found 'nan'"});
    }
    {
        const auto p = write_pair(dir, "g", k_node0, "2 4 0\n0 0 1 2 3\n1 1 two 3 4\n");
        expect_read_error(p, {at_line(dir / "g.ele", 3), "node 2 of tet 1", "found 'two'"});
    }
}

TEST(TetgenShared, ReadsArmadillo)
{
    const auto p = shared_mesh("armadillo_4k.node");
    if (!p) GTEST_SKIP() << "shared mesh absent";
    expect_valid_with_counts(io::read_mesh(p->string()), 1180, 3717);
}
