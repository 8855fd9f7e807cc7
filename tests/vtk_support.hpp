#pragma once
// Helpers shared by the VTK tests (our readers and writers; meshio and the VTK library): a jittered grid mesh
// with objects and labels, sample fields, mesh comparison, reference files for the Python checks.
#include "support.hpp"

#include "tethash/io/vtk_legacy.hpp"
#include "tethash/io/vtu.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

namespace tethash::test {

/// A jittered nx × ny × nz grid of cubes, each split into 6 tets (Kuhn), as two objects
/// (x < half and x ≥ half) with labels, coordinates that float32 cannot hold exactly.
inline TetMesh grid_mesh(int nx = 3, int ny = 2, int nz = 2)
{
    TetMesh m;
    const int px = nx + 1, py = ny + 1, pz = nz + 1;
    m.positions.resize(px * py * pz, 3);
    const auto id = [&](int i, int j, int k) { return static_cast<Index>(i + px * (j + py * k)); };
    for (int k = 0; k < pz; ++k)
        for (int j = 0; j < py; ++j)
            for (int i = 0; i < px; ++i) {
                const Index v = id(i, j, k);
                m.positions(v, 0) = i / 3.0 + 0.01 * std::sin(1.0 + v);
                m.positions(v, 1) = j * 0.1 + 0.01 * std::cos(2.0 * v);
                m.positions(v, 2) = k * std::sqrt(2.0) + 1e-7 * v;
            }
    std::vector<std::array<Index, 4>> tets;
    for (int k = 0; k < nz; ++k)
        for (int j = 0; j < ny; ++j)
            for (int i = 0; i < nx; ++i)
                for (const auto& t : kuhn_tets(i, j, k, id)) {
                    tets.push_back(t);
                    m.tet_object.push_back(i < nx / 2 ? 0 : 1);
                    m.tet_label.push_back(100 + i + 10 * k);
                }
    m.tets = matrix_of<Tets>(tets);
    m.vertex_object.assign(static_cast<std::size_t>(m.num_vertices()), 0);
    for (std::size_t t = 0; t < tets.size(); ++t)
        for (Index v : tets[t])
            m.vertex_object[static_cast<std::size_t>(v)] = m.tet_object[t];
    return m;
}

inline io::Fields sample_fields(const TetMesh& m)
{
    io::Fields f;
    io::Field vel{"velocity", 3, {}}, contact{"contact", 1, {}}, stress{"stress", 1, {}};
    for (Index v = 0; v < m.num_vertices(); ++v) {
        for (int k = 0; k < 3; ++k)
            vel.values.push_back(0.1 * v + k / 7.0);
        contact.values.push_back(v % 3 == 0 ? 1.0 : 0.0);
    }
    for (Index t = 0; t < m.num_tets(); ++t)
        stress.values.push_back(std::exp(-0.1 * t));
    f.point = {vel, contact};
    f.cell = {stress};
    return f;
}

inline void expect_same_mesh(const TetMesh& a, const TetMesh& b, double tol, const std::string& what)
{
    ASSERT_EQ(a.num_vertices(), b.num_vertices()) << what;
    ASSERT_EQ(a.num_tets(), b.num_tets()) << what;
    for (Index v = 0; v < a.num_vertices(); ++v)
        for (int k = 0; k < 3; ++k) {
            if (tol == 0)
                ASSERT_EQ(a.positions(v, k), b.positions(v, k)) << what << " vertex " << v;
            else
                ASSERT_NEAR(a.positions(v, k), b.positions(v, k), tol * (1 + std::abs(a.positions(v, k))))
                    << what << " vertex " << v;
        }
    for (Index t = 0; t < a.num_tets(); ++t)
        for (int k = 0; k < 4; ++k)
            ASSERT_EQ(a.tets(t, k), b.tets(t, k)) << what << " tet " << t;
}

inline void write_reference(const std::filesystem::path& dir, const TetMesh& m)
{
    std::ofstream p(dir / "ref_points.txt"), t(dir / "ref_tets.txt");
    p.precision(17);
    for (Index v = 0; v < m.num_vertices(); ++v)
        p << m.positions(v, 0) << ' ' << m.positions(v, 1) << ' ' << m.positions(v, 2) << '\n';
    for (Index i = 0; i < m.num_tets(); ++i)
        t << m.tets(i, 0) << ' ' << m.tets(i, 1) << ' ' << m.tets(i, 2) << ' ' << m.tets(i, 3) << '\n';
}

inline TetMesh read_reference(const std::filesystem::path& dir)
{
    std::vector<double> p;
    std::vector<Index> t;
    {
        std::ifstream in(dir / "ref_points.txt");
        for (double x; in >> x;)
            p.push_back(x);
    }
    {
        std::ifstream in(dir / "ref_tets.txt");
        for (double x; in >> x;)
            t.push_back(static_cast<Index>(x));
    }
    TetMesh m;
    m.positions.resize(static_cast<Eigen::Index>(p.size() / 3), 3);
    std::copy(p.begin(), p.end(), m.positions.data());
    m.tets.resize(static_cast<Eigen::Index>(t.size() / 4), 4);
    std::copy(t.begin(), t.end(), m.tets.data());
    return m;
}

struct SampleFiles {
    TetMesh mesh;
    io::Fields fields;
};

/// The grid mesh with its sample fields, written into `dir` in each format and encoding we write (ours.vtu,
/// ours_binary.vtk, ours_ascii.vtk) with its reference text for the Python checks. Returns what it wrote.
inline SampleFiles write_ours_and_reference(const std::filesystem::path& dir)
{
    SampleFiles s{grid_mesh(), {}};
    s.fields = sample_fields(s.mesh);
    io::write_vtu((dir / "ours.vtu").string(), s.mesh, s.fields);
    io::write_vtk((dir / "ours_binary.vtk").string(), s.mesh, s.fields, true);
    io::write_vtk((dir / "ours_ascii.vtk").string(), s.mesh, s.fields, false);
    write_reference(dir, s.mesh);
    return s;
}

} // namespace tethash::test
