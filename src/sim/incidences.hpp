#pragma once
// Vertex-to-row incidences of an index matrix (private to tethash::sim): the block-descent set-up and the
// inversion guard look up a vertex's springs and tets through them.

#include <cstddef>
#include <cstdint>
#include <vector>

namespace tethash::sim::detail {

/// The rows of an index matrix (springs' edges, tets) at each vertex, in compressed form: vertex i's are
/// entries[start[i] .. start[i + 1]), in row order, each the row or, with `with_column`, cols · row + column.
struct Incidences {
    std::vector<std::int32_t> start, entries;
};

template <class IndexMatrix> Incidences incidences(const IndexMatrix& m, std::size_t num_vertices, bool with_column)
{
    const auto rows = static_cast<std::int64_t>(m.rows());
    const int cols = static_cast<int>(m.cols());
    Incidences out;
    out.start.assign(num_vertices + 1, 0);
    out.entries.resize(static_cast<std::size_t>(rows * cols));
    for (std::int64_t r = 0; r < rows; ++r)
        for (int c = 0; c < cols; ++c)
            ++out.start[static_cast<std::size_t>(m(r, c)) + 1];
    for (std::size_t i = 0; i < num_vertices; ++i)
        out.start[i + 1] += out.start[i];
    std::vector<std::int32_t> fill(out.start.begin(), out.start.end() - 1);
    for (std::int64_t r = 0; r < rows; ++r)
        for (int c = 0; c < cols; ++c)
            out.entries[static_cast<std::size_t>(fill[static_cast<std::size_t>(m(r, c))]++)] =
                static_cast<std::int32_t>(with_column ? cols * r + c : r);
    return out;
}

} // namespace tethash::sim::detail
