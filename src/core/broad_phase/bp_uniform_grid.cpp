// The dense uniform grid as a broad phase (docs/partitions.md): an array of cells over the
// vertices' bounding box, the vertices counting-sorted into it, each tet box enumerating the cells it overlaps.
//
// Cell (x, y, z) of the vertices' box [o, h] holds the vertices p with
// cell_coord(p, o, 1/l) = (x, y, z); cells are numbered z fastest so that the cells of one (x, y) column of a tet box
// are one contiguous range of the sorted vertices. A tet box's cell range uses the same expression for its corners
// (monotone: a vertex in the box has its cell in the range), clamped to the grid (every tet box lies in the vertices'
// box: its corners are vertex coordinates). Each vertex is in one cell, so each pair is found once.
#include "bp_common.hpp"

#include "tethash/error.hpp"

#include <algorithm>
#include <sstream>

namespace tethash::detail {

namespace {

class UniformGrid final : public BroadPhaseBase {
  public:
    std::int64_t nodes() const override { return m_cells; }

    static constexpr std::int64_t max_cells = std::int64_t{1} << 28;
    static constexpr std::int64_t max_bytes = std::int64_t{1} << 31;

  private:
    /// Throws Error when the grid would need more than max_cells cells or max_bytes bytes.
    bool build_phase(const PartitionScene& scene, int threads) override;
    void query_phase(const PartitionScene& scene, std::vector<CandidateSink>& sinks) override;
    std::int64_t structure_bytes() const override { return bytes_of(m_start, m_ids, m_xyz, m_cell); }

    std::int64_t m_cells = 0;
    std::int64_t m_dims[3] = {0, 0, 0};
    double m_origin[3] = {0, 0, 0};   // the vertices' min corner
    double m_inv = 1;                 // 1 / cell size
    std::vector<Index> m_start;       // cells + 1: the vertices of cell c are m_ids[m_start[c], m_start[c + 1])
    std::vector<Index> m_ids;         // vertices by cell (z fastest, then y, then x)
    std::vector<double> m_xyz;        // their positions in that order (3 per vertex)
    std::vector<std::int32_t> m_cell; // per vertex: its cell
};

bool UniformGrid::build_phase(const PartitionScene& s, int /*threads*/)
{
    const Index n = s.num_vertices;
    const double* P = s.positions;
    m_cells = 0;
    if (n == 0 || s.num_tets == 0) return false;

    const Box box = vertex_box(s);
    const double *lo = box.lo, *hi = box.hi;
    const double inv = 1.0 / s.cell_size;
    std::copy(lo, lo + 3, m_origin);
    m_inv = inv;
    double cells = 1;
    for (int a = 0; a < 3; ++a) {
        m_dims[a] = cell_coord(hi[a], lo[a], inv) + 1;
        cells *= static_cast<double>(m_dims[a]);
    }
    const double bytes = (cells + 1) * sizeof(Index) +
                         static_cast<double>(n) * (sizeof(Index) + 3 * sizeof(double) + sizeof(std::int32_t) + 1);
    if (cells > static_cast<double>(max_cells) || bytes > static_cast<double>(max_bytes)) {
        std::ostringstream msg;
        msg << "uniform grid: cell size " << s.cell_size << " over the vertices' box " << hi[0] - lo[0] << " × "
            << hi[1] - lo[1] << " × " << hi[2] - lo[2] << " needs " << cells << " cells (" << m_dims[0] << " × "
            << m_dims[1] << " × " << m_dims[2] << "), " << bytes << " bytes (limits: " << max_cells << " cells, "
            << max_bytes << " bytes); use a larger cell size or the spatial hash (method hash)";
        throw Error(msg.str());
    }
    m_cells = static_cast<std::int64_t>(cells);
    const std::int64_t dy = m_dims[1], dz = m_dims[2];

    // Counting sort of the vertices by cell.
    m_cell.resize(static_cast<std::size_t>(n));
    m_start.assign(static_cast<std::size_t>(m_cells) + 1, 0);
    for (Index v = 0; v < n; ++v) {
        const double* p = P + 3 * static_cast<std::size_t>(v);
        const std::int64_t c =
            (cell_coord(p[0], lo[0], inv) * dy + cell_coord(p[1], lo[1], inv)) * dz + cell_coord(p[2], lo[2], inv);
        m_cell[static_cast<std::size_t>(v)] = static_cast<std::int32_t>(c);
        ++m_start[static_cast<std::size_t>(c) + 1];
    }
    for (std::int64_t c = 0; c < m_cells; ++c)
        m_start[static_cast<std::size_t>(c) + 1] += m_start[static_cast<std::size_t>(c)];
    m_ids.resize(static_cast<std::size_t>(n));
    m_xyz.resize(3 * static_cast<std::size_t>(n));
    for (Index v = 0; v < n; ++v) {
        const Index i = m_start[static_cast<std::size_t>(m_cell[static_cast<std::size_t>(v)])]++;
        m_ids[static_cast<std::size_t>(i)] = v;
        std::copy(P + 3 * static_cast<std::size_t>(v), P + 3 * static_cast<std::size_t>(v) + 3,
                  m_xyz.begin() + 3 * static_cast<std::ptrdiff_t>(i));
    }
    for (std::int64_t c = m_cells; c > 0; --c) // the increments shifted every start by one cell: shift back
        m_start[static_cast<std::size_t>(c)] = m_start[static_cast<std::size_t>(c) - 1];
    m_start[0] = 0;
    return true;
}

void UniformGrid::query_phase(const PartitionScene& s, std::vector<CandidateSink>& sinks)
{
    const double* lo = m_origin;
    const double inv = m_inv;
    const std::int64_t dy = m_dims[1], dz = m_dims[2];
    for_each_index(s.num_tets, 256, sinks, [&](Index t, std::vector<CandidatePair>& out) {
        double blo[3], bhi[3];
        tet_box(s, t, blo, bhi);
        std::int64_t c0[3], c1[3];
        for (int a = 0; a < 3; ++a) {
            c0[a] = std::clamp<std::int64_t>(cell_coord(blo[a], lo[a], inv), 0, m_dims[a] - 1);
            c1[a] = std::clamp<std::int64_t>(cell_coord(bhi[a], lo[a], inv), 0, m_dims[a] - 1);
        }
        const bool tet_static = s.tet_static[t] != 0;
        for (std::int64_t x = c0[0]; x <= c1[0]; ++x)
            for (std::int64_t y = c0[1]; y <= c1[1]; ++y) {
                const std::size_t column = static_cast<std::size_t>((x * dy + y) * dz);
                const Index first = m_start[column + static_cast<std::size_t>(c0[2])];
                const Index last = m_start[column + static_cast<std::size_t>(c1[2]) + 1];
                for (Index i = first; i < last; ++i) {
                    if (!in_box(m_xyz.data() + 3 * static_cast<std::size_t>(i), blo, bhi)) continue;
                    add_candidate(s, m_ids[static_cast<std::size_t>(i)], t, tet_static, m_static.data(), out);
                }
            }
    });
}

} // namespace

std::unique_ptr<BroadPhase> make_uniform_grid()
{
    return std::make_unique<UniformGrid>();
}

} // namespace tethash::detail
