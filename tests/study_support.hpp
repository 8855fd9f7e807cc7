#pragma once
// Helpers of the study tests (test_study.cpp, test_cli_study.cpp): a small scene and the deterministic part of
// a study table.
#include "tethash/io/mesh_io.hpp"
#include "tethash/meshing/generate.hpp"
#include "tethash/study/table.hpp"

#include <filesystem>
#include <string>
#include <utility>
#include <vector>

namespace tethash::test {

/// Two overlapping generated boxes written as DIR/a.vtu and DIR/b.vtu, the second shifted by `shift`; returns
/// "DIR/a.vtu+DIR/b.vtu" (one scene of two objects for --mesh).
inline std::string two_boxes(const std::filesystem::path& dir, int resolution, const Eigen::RowVector3d& shift)
{
    meshing::GenerateParams p;
    p.shape = "box";
    p.resolution = resolution;
    TetMesh a = meshing::generate(p);
    TetMesh b = a;
    b.positions.rowwise() += shift;
    io::write_mesh((dir / "a.vtu").string(), a);
    io::write_mesh((dir / "b.vtu").string(), b);
    return (dir / "a.vtu").string() + "+" + (dir / "b.vtu").string();
}

/// The table without its timing columns (what must not change between runs, shards or thread counts).
inline study::Table deterministic(const study::Table& t)
{
    study::Table d;
    std::vector<std::size_t> keep;
    for (std::size_t c = 0; c < t.columns.size(); ++c)
        if (!study::is_timing_column(t.columns[c])) {
            keep.push_back(c);
            d.columns.push_back(t.columns[c]);
        }
    for (const auto& r : t.rows) {
        study::Row x;
        for (auto c : keep)
            x.push_back(r[c]);
        d.rows.push_back(std::move(x));
    }
    return d;
}

} // namespace tethash::test
