// Gmsh .msh reader and writer: hand-made ASCII and binary files (2.2 and 4.1, both byte orders),
// our writer -> our reader, meshio -> us and us -> meshio, every class of bad input, the shared meshes.
#include "io_formats_support.hpp"

#include "tethash/io/gmsh.hpp"

#include <algorithm>
#include <cstring>
#include <limits>

using namespace tethash;
using namespace tethash::test;

namespace {

/// Builds binary .msh content; `swap` writes every multi-byte value big-endian (on this little-endian host).
struct Bytes {
    bool swap = false;
    std::string s;
    template <class T> std::size_t put(T v)
    {
        const std::size_t at = s.size();
        char b[sizeof(T)];
        std::memcpy(b, &v, sizeof(T));
        if (swap) std::reverse(b, b + sizeof(T));
        s.append(b, sizeof(T));
        return at;
    }
    void text(const std::string& t) { s += t; }
    void size_t_(std::uint64_t v) { put(v); }
    void int_(std::int32_t v) { put(v); }
};

/// two_tets() in binary MSH 4.1: one volume entity with physical tag 7, a triangle block skipped.
/// `nan_at` receives the offset of the y coordinate of node 3 (set to NaN when `nan` is true).
std::string binary41(bool swap, bool nan = false, std::size_t* nan_at = nullptr)
{
    Bytes b{swap, {}};
    b.text("$MeshFormat\n4.1 1 8\n");
    b.int_(1);
    b.text("\n$EndMeshFormat\n$Entities\n");
    for (std::uint64_t c : {0, 0, 0, 1})
        b.size_t_(c);
    b.int_(1);
    for (double v : {0., 0., 0., 1., 1., 1.})
        b.put(v);
    b.size_t_(1);
    b.int_(7);
    b.size_t_(0);
    b.text("\n$EndEntities\n$Nodes\n");
    for (std::uint64_t c : {1, 5, 1, 5})
        b.size_t_(c);
    b.int_(3);
    b.int_(1);
    b.int_(0);
    b.size_t_(5);
    for (std::uint64_t t = 1; t <= 5; ++t)
        b.size_t_(t);
    const TetMesh ref = two_tets();
    for (Index v = 0; v < 5; ++v)
        for (int a = 0; a < 3; ++a) {
            const bool bad = nan && v == 2 && a == 1;
            const std::size_t at = b.put(bad ? std::numeric_limits<double>::quiet_NaN() : ref.positions(v, a));
            if (bad && nan_at) *nan_at = at;
        }
    b.text("\n$EndNodes\n$Elements\n");
    for (std::uint64_t c : {2, 3, 1, 3})
        b.size_t_(c);
    b.int_(2);
    b.int_(1);
    b.int_(2);
    b.size_t_(1);
    for (std::uint64_t c : {1, 1, 2, 3})
        b.size_t_(c);
    b.int_(3);
    b.int_(1);
    b.int_(4);
    b.size_t_(2);
    for (std::uint64_t c : {2, 1, 2, 3, 4, 3, 2, 3, 4, 5})
        b.size_t_(c);
    b.text("\n$EndElements\n");
    return b.s;
}

/// two_tets() in binary MSH 2.2 with node tags 3 5 7 9 11: a point, the first tet (physical 7),
/// the second tet (physical 0, elementary 2).
std::string binary22(bool swap)
{
    Bytes b{swap, {}};
    b.text("$MeshFormat\n2.2 1 8\n");
    b.int_(1);
    b.text("\n$EndMeshFormat\n$Nodes\n5\n");
    const TetMesh ref = two_tets();
    for (Index v = 0; v < 5; ++v) {
        b.int_(3 + 2 * v);
        for (int a = 0; a < 3; ++a)
            b.put(ref.positions(v, a));
    }
    b.text("\n$EndNodes\n$Elements\n3\n");
    for (std::int32_t c : {15, 1, 2, /*elem*/ 1, 0, 1, 3})
        b.int_(c);
    for (std::int32_t c : {4, 2, 2, /*elem*/ 2, 7, 1, 3, 5, 7, 9, /*elem*/ 3, 0, 2, 5, 7, 9, 11})
        b.int_(c);
    b.text("\n$EndElements\n");
    return b.s;
}

void expect_two_tets(const TetMesh& m, const std::vector<Index>& labels, const std::string& what)
{
    expect_same_geometry(m, two_tets(), what);
    EXPECT_EQ(m.tet_label, labels) << what;
}

} // namespace

// ---- hand-made ASCII files --------------------------------------------------------------------

TEST(GmshAscii, Reads41WithEntitiesSparseTagsAndSkippedSections)
{
    io::ReadNotes notes;
    const TetMesh m = io::read_msh(data_file("gmsh/two_tets_41.msh").string(), &notes);
    // Nodes in file order: tags 10 20 30 | 50 40.
    ASSERT_EQ(m.num_vertices(), 5);
    ASSERT_EQ(m.num_tets(), 2);
    const TetMesh ref = two_tets();
    const Index order[5] = {0, 1, 2, 4, 3};
    for (Index v = 0; v < 5; ++v)
        EXPECT_TRUE(m.positions.row(v) == ref.positions.row(order[v])) << v;
    expect_same_tets_by_coordinates(m, ref, "two_tets_41");
    EXPECT_EQ(m.tet_label, (std::vector<Index>{7, 2})); // entity 1 has physical 7; entity 2 has none
    EXPECT_EQ(notes.skipped_cells, 2);
    EXPECT_TRUE(validate(m).ok());
}

TEST(GmshAscii, Reads22PhysicalThenElementaryTags)
{
    io::ReadNotes notes;
    const TetMesh m = io::read_msh(data_file("gmsh/two_tets_22.msh").string(), &notes);
    expect_two_tets(m, {7, 2}, "two_tets_22");
    EXPECT_EQ(notes.skipped_cells, 2);
}

TEST(GmshAscii, SkipsUnknownSectionsLikeSurface)
{
    const auto dir = temp_dir();
    std::string text = read_text(data_file("gmsh/two_tets_41.msh"));
    text += "$Surface\n2\n1 2 3\n2 3 4\n$EndSurface\n$Whatever\n$Nodes inside an unknown section\n$EndWhatever\n";
    write_text(dir / "s.msh", text);
    const TetMesh m = io::read_mesh((dir / "s.msh").string());
    EXPECT_EQ(m.num_tets(), 2);
}

TEST(GmshAscii, UnknownElementTypeIsSkippedLineByLine)
{
    const auto dir = temp_dir();
    std::string text = read_text(data_file("gmsh/two_tets_41.msh"));
    // Replace the point block (type 15) by a block of an element type unknown to the reader.
    const std::string from = "4 4 1 4\n0 5 15 1\n1 10\n";
    ASSERT_NE(text.find(from), std::string::npos);
    text.replace(text.find(from), from.size(), "4 5 1 5\n0 5 77 2\n1 10 20 30 40 50 60\n5 1 2\n");
    write_text(dir / "u.msh", text);
    io::ReadNotes notes;
    const TetMesh m = io::read_msh((dir / "u.msh").string(), &notes);
    EXPECT_EQ(m.num_tets(), 2);
    EXPECT_EQ(notes.skipped_cells, 3);
}

TEST(GmshAscii, CrLfLineEnds)
{
    const auto dir = temp_dir();
    std::string text = read_text(data_file("gmsh/two_tets_22.msh")), crlf;
    for (char c : text) {
        if (c == '\n') crlf += '\r';
        crlf += c;
    }
    write_text(dir / "crlf.msh", crlf);
    expect_two_tets(io::read_msh((dir / "crlf.msh").string()), {7, 2}, "crlf");
}

// ---- hand-made binary files -------------------------------------------------------------------

TEST(GmshBinary, Reads41And22LittleAndBigEndian)
{
    const auto dir = temp_dir();
    for (bool v41 : {true, false})
        for (bool swap : {false, true}) {
            const auto p = dir / (std::string(swap ? "be" : "le") + (v41 ? "41" : "22") + ".msh");
            write_text(p, v41 ? binary41(swap) : binary22(swap));
            io::ReadNotes notes;
            // 4.1: both tets in the entity of physical tag 7; 2.2: the second tet has no physical tag (elementary 2).
            expect_two_tets(io::read_msh(p.string(), &notes), v41 ? std::vector<Index>{7, 7} : std::vector<Index>{7, 2},
                            p.string());
            EXPECT_EQ(notes.skipped_cells, 1);
        }
}

TEST(GmshBinary, SkipsBinarySectionsItDoesNotNeed)
{
    const auto dir = temp_dir();
    Bytes data{false, {}};
    data.text("$NodeData\n1\n\"t\"\n1\n0.0\n3\n0\n1\n5\n");
    for (std::int32_t t = 1; t <= 5; ++t) {
        data.int_(t);
        data.put(t == 3 ? 36.0 : -1.5); // arbitrary bytes, including '$' and line breaks
    }
    data.text("\n$End\n$EndNodeData\n");
    write_text(dir / "nd.msh", binary41(false) + data.s);
    expect_two_tets(io::read_msh((dir / "nd.msh").string()), {7, 7}, "binary $NodeData");
}

// ---- our writer -> our reader -------------------------------------------------------------------

TEST(GmshWrite, RoundTripAsciiAndBinaryExact)
{
    const auto dir = temp_dir();
    const TetMesh m = grid_mesh(3, 2, 3);
    for (bool binary : {false, true}) {
        const auto p = dir / (binary ? "b.msh" : "a.msh");
        io::write_msh(p.string(), m, binary);
        const TetMesh r = io::read_msh(p.string());
        expect_same_geometry(r, m, p.string());
        EXPECT_EQ(r.tet_label, m.tet_label) << p;
    }
}

TEST(GmshWrite, InterleavedLabelsKeepTetOrder)
{
    const auto dir = temp_dir();
    TetMesh m = grid_mesh(2, 2, 2, /*two_objects=*/true);
    for (std::size_t t = 0; t < m.tet_label.size(); ++t)
        m.tet_label[t] = static_cast<Index>(t % 3 + 1);
    for (bool binary : {false, true}) {
        const auto p = dir / (binary ? "b.msh" : "a.msh");
        io::write_msh(p.string(), m, binary);
        const TetMesh r = io::read_msh(p.string());
        expect_same_geometry(r, m, p.string());
        EXPECT_EQ(r.tet_label, m.tet_label);
    }
}

TEST(GmshWrite, WriteMeshByExtensionIsAtomic)
{
    const auto dir = temp_dir();
    const TetMesh m = grid_mesh(1, 1, 1);
    io::write_mesh((dir / "x.msh").string(), m);
    EXPECT_EQ(io::read_mesh((dir / "x.msh").string()).num_tets(), 6);
    // A bad mesh (index past the end) is refused and leaves the good file and no temporary behind.
    TetMesh bad = m;
    bad.tets(0, 0) = 1000;
    EXPECT_THROW(io::write_msh((dir / "x.msh").string(), bad), Error);
    EXPECT_EQ(io::read_mesh((dir / "x.msh").string()).num_tets(), 6);
    int files = 0;
    for ([[maybe_unused]] const auto& e : std::filesystem::directory_iterator(dir))
        ++files;
    EXPECT_EQ(files, 1);
}

// ---- meshio interop ---------------------------------------------------------------------------

TEST(GmshMeshio, WeReadWhatMeshioWrites)
{
    TETHASH_SKIP_WITHOUT_PYTHON(py, "meshio numpy");
    const auto dir = temp_dir();
    const TetMesh ref = grid_mesh(3, 2, 3);
    const RunResult r = meshio_writes(py, dir, ref, R"PY(
out = sys.argv[2]
n = len(pts)
splits = np.flatnonzero(np.diff(labels)) + 1
blocks = np.split(np.arange(len(tets)), splits)
cells = [("tetra", tets[b]) for b in blocks]
phys = [labels[b] for b in blocks]
geo = [labels[b] - 9 for b in blocks]
tri = np.array([[0, 1, 2], [1, 2, 3]])
m22 = meshio.Mesh(pts, cells + [("triangle", tri)],
                  cell_data={"gmsh:physical": phys + [np.array([99, 99])], "gmsh:geometrical": geo + [np.array([50, 50])]})
meshio.write(out + "/m22a.msh", m22, file_format="gmsh22", binary=False)
meshio.write(out + "/m22b.msh", m22, file_format="gmsh22", binary=True)
# 4.1 with one cell block and no entity information: labels are the entity (geometrical) tag.
one = meshio.Mesh(pts, [("tetra", tets)], cell_data={"gmsh:physical": [np.full(len(tets), 5)], "gmsh:geometrical": [np.full(len(tets), 3)]})
meshio.write(out + "/m41a.msh", one, file_format="gmsh", binary=False)
meshio.write(out + "/m41b.msh", one, file_format="gmsh", binary=True)
# 4.1 with entities: nodes grouped by entity (reordered), labels from the physical tags.
dim_tags = np.zeros((n, 2), dtype=int)
dim_tags[:, 0] = 3
for b, g in zip(blocks, geo):
    dim_tags[tets[b].ravel(), 1] = g[0]
ent = meshio.Mesh(pts, cells, point_data={"gmsh:dim_tags": dim_tags}, cell_data={"gmsh:physical": phys, "gmsh:geometrical": geo})
meshio.write(out + "/e41a.msh", ent, file_format="gmsh", binary=False)
meshio.write(out + "/e41b.msh", ent, file_format="gmsh", binary=True)
)PY",
                                      ".");
    ASSERT_EQ(r.status, 0) << r.out << r.err;
    for (const char* name : {"m22a.msh", "m22b.msh"}) {
        io::ReadNotes notes;
        const TetMesh m = io::read_mesh((dir / name).string(), &notes);
        expect_same_geometry(m, ref, name);
        EXPECT_EQ(m.tet_label, ref.tet_label) << name;
        EXPECT_EQ(notes.skipped_cells, 2) << name;
    }
    for (const char* name : {"m41a.msh", "m41b.msh"}) {
        const TetMesh m = io::read_mesh((dir / name).string());
        expect_same_geometry(m, ref, name);
        EXPECT_EQ(m.tet_label, std::vector<Index>(static_cast<std::size_t>(ref.num_tets()), 3)) << name;
    }
    for (const char* name : {"e41a.msh", "e41b.msh"}) {
        const TetMesh m = io::read_mesh((dir / name).string());
        expect_same_tets_by_coordinates(m, ref, name);
        EXPECT_EQ(m.tet_label, ref.tet_label) << name;
    }
}

TEST(GmshMeshio, MeshioReadsWhatWeWrite)
{
    TETHASH_SKIP_WITHOUT_PYTHON(py, "meshio numpy");
    const auto dir = temp_dir();
    const TetMesh ref = grid_mesh(3, 2, 3);
    write_reference(dir / "ref.txt", ref);
    io::write_msh((dir / "a.msh").string(), ref, false);
    io::write_msh((dir / "b.msh").string(), ref, true);
    expect_meshio_reads(py, dir, "gmsh:physical", {"a.msh", "b.msh"});
}

// ---- bad input ----------------------------------------------------------------------------------

namespace {

/// Writes two_tets_41.msh with `from` replaced by `to` (must occur) and returns its path and text.
std::pair<std::filesystem::path, std::string> edited41(const std::filesystem::path& dir, const std::string& from,
                                                       const std::string& to, const std::string& name = "bad.msh")
{
    std::string text = read_text(data_file("gmsh/two_tets_41.msh"));
    const std::size_t at = text.find(from);
    EXPECT_NE(at, std::string::npos) << from;
    if (at != std::string::npos) text.replace(at, from.size(), to);
    write_text(dir / name, text);
    return {dir / name, text};
}

} // namespace

TEST(GmshErrors, UnknownVersion)
{
    const auto dir = temp_dir();
    for (const char* v : {"3.0", "4.0", "1"}) {
        const auto [p, text] = edited41(dir, "4.1 0 8", std::string(v) + " 0 8");
        expect_read_error(p, {at_line(p, 2), "expected MSH version 2.2 or 4.1", std::string("'") + v + "'"});
    }
    write_text(dir / "v1.msh", "$NOD\n1\n1 0 0 0\n$ENDNOD\n");
    expect_read_error(dir / "v1.msh", {at_line(dir / "v1.msh", 1), "expected $MeshFormat, found '$NOD'"});
}

TEST(GmshErrors, TruncatedFile)
{
    const auto dir = temp_dir();
    std::string text = read_text(data_file("gmsh/two_tets_41.msh"));
    text = text.substr(0, text.find("0 1 0\n3 2 0 2")); // cut inside the coordinates of the first node block
    write_text(dir / "cut.msh", text);
    expect_read_error(dir / "cut.msh",
                      {(dir / "cut.msh").string() + ":", "coordinate of node 30", "found end of file"});
    // Cut inside the elements: the last tet misses nodes.
    text = read_text(data_file("gmsh/two_tets_41.msh"));
    text = text.substr(0, text.find("4 20 30 40 50") + 8);
    write_text(dir / "cut2.msh", text);
    expect_read_error(dir / "cut2.msh", {"node tag of element 4", "found end of file"});
}

TEST(GmshErrors, WrongCounts)
{
    const auto dir = temp_dir();
    {
        const auto [p, text] = edited41(dir, "2 5 10 50", "2 6 10 50", "nodes.msh");
        expect_read_error(p, {at_line(p, line_of(text, "$EndNodes")), "expected 6 nodes", "found 5"});
    }
    {
        const auto [p, text] = edited41(dir, "4 4 1 4", "4 5 1 4", "elements.msh");
        expect_read_error(p, {at_line(p, line_of(text, "$EndElements")), "expected 5 elements", "found 4"});
    }
    {
        // A block claims more nodes than the header allows.
        const auto [p, text] = edited41(dir, "3 2 0 2", "3 2 0 3", "block.msh");
        expect_read_error(p, {at_line(p, line_of(text, "3 2 0 3")), "at most 2 nodes in node block 2", "found 3"});
    }
}

TEST(GmshErrors, NodeTagPastTheEnd)
{
    const auto dir = temp_dir();
    const auto [p, text] = edited41(dir, "4 20 30 40 50", "4 20 30 40 99");
    expect_read_error(p, {at_line(p, line_of(text, "4 20 30 40 99")), "element 4: node tag 99 is not in $Nodes"});
}

TEST(GmshErrors, NanAndInfCoordinates)
{
    const auto dir = temp_dir();
    {
        const auto [p, text] = edited41(dir, "0 1 0\n3 2 0 2", "0 nan 0\n3 2 0 2", "nan.msh");
        expect_read_error(
            p, {at_line(p, line_of(text, "0 nan 0")), "expected a finite y coordinate of node 30", "found 'nan'"});
    }
    {
        const auto [p, text] = edited41(dir, "1 1 1\n0 0 1\n$EndNodes", "1 1 -inf\n0 0 1\n$EndNodes", "inf.msh");
        expect_read_error(p, {at_line(p, line_of(text, "1 1 -inf")), "z coordinate of node 50", "found '-inf'"});
    }
}

TEST(GmshErrors, GarbageTokens)
{
    const auto dir = temp_dir();
    {
        const auto [p, text] = edited41(dir, "0 0 0\n1 0 0\n0 1 0\n", "0 0 0\n1 zero 0\n0 1 0\n", "g1.msh");
        expect_read_error(p, {at_line(p, line_of(text, "1 zero 0")), "y coordinate of node 20", "found 'zero'"});
    }
    {
        const auto [p, text] = edited41(dir, "3 1 4 1\n", "3 1 4 x1\n", "g2.msh");
        expect_read_error(p, {at_line(p, line_of(text, "3 1 4 x1")), "found 'x1'"});
    }
    {
        const auto [p, text] = edited41(dir, "$EndNodes", "$EndNodez", "g3.msh");
        expect_read_error(p, {at_line(p, line_of(text, "$EndNodez")), "expected $EndNodes, found '$EndNodez'"});
    }
}

TEST(GmshErrors, StructureProblems)
{
    const auto dir = temp_dir();
    {
        const auto [p, text] = edited41(dir, "$EndComments\n", "", "noend.msh");
        expect_read_error(p, {at_line(p, line_of(text, "$Comments")), "section $Comments has no $EndComments"});
    }
    {
        const auto [p, text] = edited41(dir, "50\n40\n", "50\n10\n", "dup.msh");
        expect_read_error(p, {p.string() + ":", "node tag 10 appears twice"});
    }
    {
        std::string text = read_text(data_file("gmsh/two_tets_41.msh"));
        text = text.substr(0, text.find("$Elements"));
        write_text(dir / "noel.msh", text);
        expect_read_error(dir / "noel.msh", {(dir / "noel.msh").string() + ": no $Elements section"});
    }
}

TEST(GmshErrors, BinaryProblemsNameTheByteOffset)
{
    const auto dir = temp_dir();
    {
        // Truncated in the middle of the node coordinates.
        const std::string full = binary41(false);
        const std::size_t cut = full.find("$EndNodes") - 20;
        write_text(dir / "cut.msh", full.substr(0, cut));
        expect_read_error(dir / "cut.msh", {(dir / "cut.msh").string() + ": byte ", "found end of file"});
    }
    {
        std::size_t at = 0;
        write_text(dir / "nan.msh", binary41(true, true, &at));
        expect_read_error(dir / "nan.msh", {(dir / "nan.msh").string() + ": byte " + std::to_string(at) + ":",
                                            "finite y coordinate of node 3", "found nan"});
    }
    {
        std::string s = binary22(false);
        const std::size_t at = std::string("$MeshFormat\n2.2 1 8\n").size();
        s[at] = 2; // the byte-order check reads 2 instead of 1
        write_text(dir / "order.msh", s);
        expect_read_error(dir / "order.msh", {(dir / "order.msh").string() + ": byte " + std::to_string(at) + ":",
                                              "expected the integer 1", "found 2"});
    }
    {
        // A tet refers to node tag 4 (tags are 3 5 7 9 11).
        std::string s = binary22(false);
        std::int32_t from[4] = {5, 7, 9, 11}, to[4] = {5, 7, 9, 4};
        const std::size_t at = s.find(std::string(reinterpret_cast<const char*>(from), 16));
        ASSERT_NE(at, std::string::npos);
        s.replace(at, 16, std::string(reinterpret_cast<const char*>(to), 16));
        write_text(dir / "tag.msh", s);
        expect_read_error(dir / "tag.msh", {(dir / "tag.msh").string() + ": byte " + std::to_string(at + 12) + ":",
                                            "element 3: node tag 4 is not in $Nodes"});
    }
}

// ---- the shared real meshes -------------------------------------------------------------------

TEST(GmshShared, ReadsEveryShared41Mesh)
{
    // Skipped elements (boundary triangles and such) are not checked here.
    const std::optional<std::int64_t> any;
    expect_shared_meshes({{"screw.msh", 1732, 6059, 0, any},
                          {"P1.msh", 1585, 6414, 8, any},
                          {"32770_octocat.msh", 6133, 21426, 0, any},
                          {"mat100x100t40.msh", 20000, 58806, 0, any}});
}
