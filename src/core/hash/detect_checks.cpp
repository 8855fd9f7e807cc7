// Checks of the detector's input (topology, positions, object flags) and the mean edge length behind
// relative cell sizes: shared by the Detector and the oracle (detect_checks.hpp).
#include "detect_checks.hpp"

#include "tethash/detect.hpp"
#include "tethash/error.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>

namespace tethash {

double mean_edge_length(const PositionsRef& positions, const TetsRef& tets)
{
    const Index n = static_cast<Index>(positions.rows());
    std::vector<std::uint64_t> keys;
    keys.reserve(static_cast<std::size_t>(tets.rows()) * 6);
    static constexpr int pairs[6][2] = {{0, 1}, {0, 2}, {0, 3}, {1, 2}, {1, 3}, {2, 3}};
    for (Eigen::Index t = 0; t < tets.rows(); ++t)
        for (const auto& e : pairs) {
            Index a = tets(t, e[0]), b = tets(t, e[1]);
            if (a < 0 || b < 0 || a >= n || b >= n)
                throw Error("mean_edge_length: tet " + std::to_string(t) + " has a vertex index out of range [0, " +
                            std::to_string(n) + ")");
            if (a == b) continue;
            if (a > b) std::swap(a, b);
            keys.push_back((static_cast<std::uint64_t>(a) << 32) | static_cast<std::uint32_t>(b));
        }
    std::sort(keys.begin(), keys.end());
    keys.erase(std::unique(keys.begin(), keys.end()), keys.end());
    if (keys.empty()) return 0.0;
    double sum = 0;
    for (std::uint64_t k : keys) {
        const Index a = static_cast<Index>(k >> 32), b = static_cast<Index>(k & 0xffffffffu);
        sum += (positions.row(a) - positions.row(b)).norm();
    }
    return sum / static_cast<double>(keys.size());
}

namespace detail {

void check_topology(const TetsRef& tets, Index num_vertices, std::span<const Index> vertex_object,
                    std::span<const Index> tet_object)
{
    if (num_vertices < 0) throw Error("number of vertices must be ≥ 0, got " + std::to_string(num_vertices));
    if (!vertex_object.empty() && static_cast<Index>(vertex_object.size()) != num_vertices)
        throw Error("vertex_object has " + std::to_string(vertex_object.size()) + " entries for " +
                    std::to_string(num_vertices) + " vertices");
    if (!tet_object.empty() && static_cast<Eigen::Index>(tet_object.size()) != tets.rows())
        throw Error("tet_object has " + std::to_string(tet_object.size()) + " entries for " +
                    std::to_string(tets.rows()) + " tets");
    for (Eigen::Index t = 0; t < tets.rows(); ++t) {
        for (int k = 0; k < 4; ++k) {
            const Index v = tets(t, k);
            // A vertex repeated within a tet is allowed: a collapsed tet has zero volume, and the inside test skips
            // it like every other degenerate tet (counted in DetectStats::degenerate_tets).
            if (v < 0 || v >= num_vertices)
                throw Error("tet " + std::to_string(t) + ": vertex index " + std::to_string(v) + " out of range [0, " +
                            std::to_string(num_vertices) + ")");
        }
    }
    for (std::size_t i = 0; i < vertex_object.size(); ++i)
        if (vertex_object[i] < 0)
            throw Error("vertex " + std::to_string(i) + ": object id " + std::to_string(vertex_object[i]) +
                        " out of range (must be ≥ 0)");
    for (std::size_t i = 0; i < tet_object.size(); ++i)
        if (tet_object[i] < 0)
            throw Error("tet " + std::to_string(i) + ": object id " + std::to_string(tet_object[i]) +
                        " out of range (must be ≥ 0)");
}

void check_positions(const PositionsRef& positions, Index num_vertices)
{
    if (positions.rows() != num_vertices)
        throw Error("positions has " + std::to_string(positions.rows()) + " rows, expected " +
                    std::to_string(num_vertices) + " (the number of vertices given to set_topology)");
    for (Eigen::Index v = 0; v < positions.rows(); ++v)
        if (!std::isfinite(positions(v, 0)) || !std::isfinite(positions(v, 1)) || !std::isfinite(positions(v, 2))) {
            std::ostringstream s;
            s << "vertex " << v << " has a non-finite position (" << positions(v, 0) << ", " << positions(v, 1) << ", "
              << positions(v, 2) << ")";
            throw Error(s.str());
        }
}

ObjectFlags object_flags(std::span<const Index> vertex_object, std::span<const Index> tet_object,
                         std::span<const ObjectOptions> objects)
{
    Index count = 1;
    for (Index o : vertex_object)
        count = std::max(count, o + 1);
    for (Index o : tet_object)
        count = std::max(count, o + 1);
    ObjectFlags f;
    f.self_collision.assign(static_cast<std::size_t>(count), 1);
    f.is_static.assign(static_cast<std::size_t>(count), 0);
    for (std::size_t k = 0; k < objects.size() && k < static_cast<std::size_t>(count); ++k) {
        f.self_collision[k] = objects[k].self_collision;
        f.is_static[k] = objects[k].is_static;
    }
    return f;
}

} // namespace detail

} // namespace tethash
