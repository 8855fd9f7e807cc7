#pragma once
// Helpers for the Gmsh / TetGen / Medit / Vega reader tests: hand-made meshes, error assertions,
// reference dumps shared with Python (meshio) scripts.
#include "support.hpp"

#include "tethash/error.hpp"
#include "tethash/io/mesh_io.hpp"

#include <cmath>
#include <functional>
#include <initializer_list>
#include <optional>
#include <string>
#include <utility>

namespace tethash::test {

/// A file under tests/data.
inline std::filesystem::path data_file(const std::string& rel)
{
    return std::filesystem::path(TETHASH_SOURCE_DIR) / "tests" / "data" / rel;
}

/// Shell-quoted path (support.hpp's quote()).
inline std::string q(const std::filesystem::path& p)
{
    return quote(p);
}

/// Writes `good` with its first `from` replaced by `to` (a failure if there is none) to `path`.
inline std::filesystem::path write_edited(const std::filesystem::path& path, std::string good, const std::string& from,
                                          const std::string& to)
{
    const std::size_t at = good.find(from);
    EXPECT_NE(at, std::string::npos) << from;
    if (at != std::string::npos) good.replace(at, from.size(), to);
    write_text(path, good);
    return path;
}

/// A hand-made good file of a format, and its variants for the error tests, written into a test's folder.
class HandMadeFile {
  public:
    explicit HandMadeFile(std::string good) : m_good(std::move(good)) {}

    /// Writes the good text with its first `from` replaced by `to` to dir/name; returns the path.
    std::filesystem::path edited(const std::filesystem::path& dir, const std::string& from, const std::string& to,
                                 const std::string& name) const
    {
        return write_edited(dir / name, m_good, from, to);
    }

    /// Writes the good text cut `extra` characters after the start of its first `at` to dir/name; returns the path.
    std::filesystem::path cut(const std::filesystem::path& dir, const std::string& at, std::size_t extra,
                              const std::string& name) const
    {
        const std::size_t end = m_good.find(at);
        EXPECT_NE(end, std::string::npos) << at;
        write_text(dir / name, m_good.substr(0, end == std::string::npos ? end : end + extra));
        return dir / name;
    }

  private:
    std::string m_good;
};

/// 1-based number of the first line of `text` that contains `needle` (0 if none).
inline int line_of(const std::string& text, const std::string& needle)
{
    const std::size_t at = text.find(needle);
    if (at == std::string::npos) return 0;
    int line = 1;
    for (std::size_t i = 0; i < at; ++i)
        if (text[i] == '\n') ++line;
    return line;
}

/// Expects reading `path` (by extension) to fail with a message containing `parts`.
inline std::string expect_read_error(const std::filesystem::path& path, std::initializer_list<std::string> parts)
{
    return expect_error([&] { (void)io::read_mesh(path.string()); }, std::vector<std::string>(parts));
}

/// "PATH:LINE:" as messages start.
inline std::string at_line(const std::filesystem::path& path, int line)
{
    return path.string() + ":" + std::to_string(line) + ":";
}

/// A small mesh: a grid of nx×ny×nz cubes, each split into 6 tets (all positively oriented), with
/// coordinates that are not short decimals (so that text round trips must be exact), labels by
/// cube layer and, if `two_objects`, the upper half as object 1.
inline TetMesh grid_mesh(int nx = 3, int ny = 2, int nz = 2, bool two_objects = false)
{
    TetMesh m;
    const int vx = nx + 1, vy = ny + 1, vz = nz + 1;
    m.positions.resize(vx * vy * vz, 3);
    auto id = [&](int i, int j, int k) { return static_cast<Index>(i + vx * (j + vy * k)); };
    for (int k = 0; k < vz; ++k)
        for (int j = 0; j < vy; ++j)
            for (int i = 0; i < vx; ++i) {
                const Index v = id(i, j, k);
                m.positions(v, 0) = i * 0.1 + std::sin(0.3 * v) * 1e-3;
                m.positions(v, 1) = j * 0.1 / 3.0 + std::cos(0.7 * v) * 1e-3;
                m.positions(v, 2) = k * std::sqrt(2.0) * 0.1 - 1e-9 * v;
            }
    std::vector<std::array<Index, 4>> tets;
    for (int k = 0; k < nz; ++k)
        for (int j = 0; j < ny; ++j)
            for (int i = 0; i < nx; ++i)
                for (std::array<Index, 4> t : kuhn_tets(i, j, k, id)) {
                    if (signed_volume(m.positions, t) < 0) std::swap(t[2], t[3]);
                    tets.push_back(t);
                    m.tet_label.push_back(10 + k);
                    if (two_objects) m.tet_object.push_back(k >= nz / 2 ? 1 : 0);
                }
    m.tets = matrix_of<Tets>(tets);
    if (two_objects) {
        m.vertex_object.assign(static_cast<std::size_t>(m.num_vertices()), 0);
        // Not a real two-object mesh (objects share vertices); only the tet-side ids matter to writers.
    }
    return m;
}

/// Writes points (%.17g), tets (0-based) and tet labels of `m` as plain text for Python to compare.
inline void write_reference(const std::filesystem::path& path, const TetMesh& m)
{
    std::ostringstream s;
    s.precision(17);
    s << m.num_vertices() << " " << m.num_tets() << "\n";
    for (Index v = 0; v < m.num_vertices(); ++v)
        s << m.positions(v, 0) << " " << m.positions(v, 1) << " " << m.positions(v, 2) << "\n";
    for (Index t = 0; t < m.num_tets(); ++t)
        s << m.tets(t, 0) << " " << m.tets(t, 1) << " " << m.tets(t, 2) << " " << m.tets(t, 3) << " "
          << (m.tet_label.empty() ? 0 : m.tet_label[static_cast<std::size_t>(t)]) << "\n";
    write_text(path, s.str());
}

/// Reads what write_reference wrote (or the same layout written by Python).
inline TetMesh read_reference(const std::filesystem::path& path)
{
    std::istringstream s(read_text(path));
    TetMesh m;
    Index n = 0, k = 0;
    s >> n >> k;
    m.positions.resize(n, 3);
    for (Index v = 0; v < n; ++v)
        s >> m.positions(v, 0) >> m.positions(v, 1) >> m.positions(v, 2);
    m.tets.resize(k, 4);
    m.tet_label.resize(static_cast<std::size_t>(k));
    for (Index t = 0; t < k; ++t)
        s >> m.tets(t, 0) >> m.tets(t, 1) >> m.tets(t, 2) >> m.tets(t, 3) >> m.tet_label[static_cast<std::size_t>(t)];
    EXPECT_TRUE(static_cast<bool>(s)) << "bad reference file " << path;
    return m;
}

/// Same counts, coordinates (exactly) and tets.
inline void expect_same_geometry(const TetMesh& a, const TetMesh& b, const std::string& what)
{
    ASSERT_EQ(a.num_vertices(), b.num_vertices()) << what;
    ASSERT_EQ(a.num_tets(), b.num_tets()) << what;
    EXPECT_TRUE(a.positions == b.positions) << what << ": coordinates differ";
    EXPECT_TRUE(a.tets == b.tets) << what << ": tets differ";
}

/// Same tets by coordinates (for files whose writer reorders the vertices): tet t of `a` and of `b`
/// have the same four corner positions in the same order.
inline void expect_same_tets_by_coordinates(const TetMesh& a, const TetMesh& b, const std::string& what)
{
    ASSERT_EQ(a.num_vertices(), b.num_vertices()) << what;
    ASSERT_EQ(a.num_tets(), b.num_tets()) << what;
    for (Index t = 0; t < a.num_tets(); ++t)
        for (int c = 0; c < 4; ++c)
            ASSERT_TRUE(a.positions.row(a.tets(t, c)) == b.positions.row(b.tets(t, c)))
                << what << ": tet " << t << " corner " << c;
}

/// Writes `script` to a file in `dir` and runs it with `py` and `args`.
inline RunResult run_python(const std::string& py, const std::filesystem::path& dir, const std::string& script,
                            const std::string& args)
{
    const auto path = dir / "script.py";
    write_text(path, script);
    return run_shell(py + " " + q(path) + " " + args);
}

/// Python: reads a reference (write_reference layout) as `pts`, `tets`, `labels`.
inline const char* python_read_reference()
{
    return R"PY(
import sys
import numpy as np
def read_reference(path):
    with open(path) as f:
        n, m = map(int, f.readline().split())
        pts = np.array([[float(x) for x in f.readline().split()] for _ in range(n)], dtype=np.float64).reshape(n, 3)
        rows = np.array([[int(x) for x in f.readline().split()] for _ in range(m)], dtype=np.int64).reshape(m, 5)
    return pts, rows[:, :4], rows[:, 4]
)PY";
}

/// Python: meshio reads every file given after the reference and checks points, tets and labels
/// (cell data `label_key`, or none if "-") against it; prints "OK name" per file.
inline std::string python_check_with_meshio(const std::string& label_key)
{
    return std::string(python_read_reference()) + R"PY(
import meshio
pts, tets, labels = read_reference(sys.argv[1])
for f in sys.argv[2:]:
    mm = meshio.read(f)
    assert mm.points.shape == pts.shape, (f, mm.points.shape, pts.shape)
    assert np.array_equal(mm.points.astype(np.float64), pts), f + ": points differ"
    blocks = [c for c in mm.cells if c.type == "tetra"]
    t = np.concatenate([c.data for c in blocks])
    assert np.array_equal(t, tets), f + ": tets differ"
    key = ")PY" +
           label_key + R"PY("
    if key != "-":
        lab = np.concatenate([d for d, c in zip(mm.cell_data[key], mm.cells) if c.type == "tetra"])
        assert np.array_equal(lab, labels), (f, "labels differ", lab[:10], labels[:10])
    print("OK", f)
)PY";
}

/// Writes `ref` to dir/ref.txt, then runs `body` with meshio imported, the reference read as `pts`, `tets`,
/// `labels` and the output path in sys.argv[2] (`out`, under `dir`).
inline RunResult meshio_writes(const std::string& py, const std::filesystem::path& dir, const TetMesh& ref,
                               const std::string& body, const std::string& out)
{
    write_reference(dir / "ref.txt", ref);
    const std::string script = std::string(python_read_reference()) +
                               "import meshio\npts, tets, labels = read_reference(sys.argv[1])\n" + body;
    return run_python(py, dir, script, q(dir / "ref.txt") + " " + q(dir / out));
}

/// meshio reads each of `files` (under `dir`) and finds the mesh of dir/ref.txt with labels `label_key`.
inline void expect_meshio_reads(const std::string& py, const std::filesystem::path& dir, const std::string& label_key,
                                std::initializer_list<std::string> files)
{
    std::string args = q(dir / "ref.txt");
    for (const std::string& f : files) {
        args.push_back(' '); // appended, not " " + q(...): g++ 12 warns falsely on that concatenation
        args.append(q(dir / f));
    }
    const RunResult r = run_python(py, dir, python_check_with_meshio(label_key), args);
    EXPECT_EQ(r.status, 0) << r.out << r.err;
    for (const std::string& f : files)
        EXPECT_NE(r.out.find("OK " + (dir / f).string()), std::string::npos) << r.out << r.err;
}

/// `m` has the given counts, is valid and has no inverted tet (what every shared real mesh must be).
inline void expect_valid_with_counts(const TetMesh& m, Index vertices, Index tets)
{
    EXPECT_EQ(m.num_vertices(), vertices);
    EXPECT_EQ(m.num_tets(), tets);
    const ValidationReport rep = validate(m);
    EXPECT_TRUE(rep.ok());
    EXPECT_EQ(rep.inverted_tets, 0);
}

/// The mesh every tests/data/*/two_tets* file holds: 5 vertices, 2 tets, in this order.
inline TetMesh two_tets()
{
    TetMesh m;
    m.positions.resize(5, 3);
    m.positions << 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 1, 1, 1;
    m.tets.resize(2, 4);
    m.tets << 0, 1, 2, 3, 1, 2, 3, 4;
    return m;
}

/// Reads tests/data/`rel` (by extension) and expects the mesh of two_tets(); returns it for the format's own checks.
inline TetMesh read_two_tets_file(const std::string& rel, io::ReadNotes* notes = nullptr)
{
    TetMesh m = io::read_mesh(data_file(rel).string(), notes);
    expect_same_geometry(m, two_tets(), rel);
    return m;
}

/// Writes `m` to dir/`written` (by extension), reads dir/`read_back` and expects the same geometry and tet
/// labels; returns what was read.
inline TetMesh round_trip(const TetMesh& m, const std::filesystem::path& dir, const std::string& written,
                          const std::string& read_back, const std::string& what)
{
    io::write_mesh((dir / written).string(), m);
    TetMesh r = io::read_mesh((dir / read_back).string());
    expect_same_geometry(r, m, what);
    EXPECT_EQ(r.tet_label, m.tet_label) << what;
    return r;
}

/// A mesh of ../shared/meshes and what reading it must give.
struct SharedMeshCase {
    const char* name;
    Index vertices, tets;
    std::int64_t inverted;                     ///< validate()'s inverted tets
    std::optional<std::int64_t> skipped_cells; ///< ReadNotes::skipped_cells, when checked
};

/// Reads the mesh of each case that is present; its counts, notes and validation must be as the case says. Skips
/// the test when none is present.
inline void expect_shared_meshes(std::initializer_list<SharedMeshCase> cases)
{
    int found = 0;
    for (const SharedMeshCase& c : cases) {
        const auto p = shared_mesh(c.name);
        if (!p) continue;
        ++found;
        io::ReadNotes notes;
        const TetMesh m = io::read_mesh(p->string(), &notes);
        EXPECT_EQ(m.num_vertices(), c.vertices) << c.name;
        EXPECT_EQ(m.num_tets(), c.tets) << c.name;
        if (c.skipped_cells) {
            EXPECT_EQ(notes.skipped_cells, *c.skipped_cells) << c.name;
        }
        const ValidationReport rep = validate(m);
        EXPECT_TRUE(rep.ok()) << c.name;
        EXPECT_EQ(rep.inverted_tets, c.inverted) << c.name;
    }
    if (!found) GTEST_SKIP() << "no shared meshes";
}

} // namespace tethash::test
