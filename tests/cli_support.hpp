#pragma once
// Input files and output readers shared by the command-line tests.

#include <sstream>
#include <string>
#include <vector>

namespace tethash::test {

/// Rows of a CSV after its '#' comment lines (the header first), split at commas; a trailing comma gives a
/// trailing empty cell.
inline std::vector<std::vector<std::string>> csv_rows(const std::string& text)
{
    std::vector<std::vector<std::string>> rows;
    std::istringstream in(text);
    for (std::string line; std::getline(in, line);) {
        if (line.empty() || line[0] == '#') continue;
        std::vector<std::string> cells;
        std::string cell;
        std::istringstream ls(line);
        while (std::getline(ls, cell, ','))
            cells.push_back(cell);
        if (line.back() == ',') cells.emplace_back();
        rows.push_back(cells);
    }
    return rows;
}

/// Two bodies in one Gmsh 2.2 file: a tet (physical tag 6, tet 0) and a unit tet (physical tag 5, tet 1); the
/// first vertex of tet 0 (node 5, 0-based vertex 4) lies inside the unit tet; node 9 belongs to no tet.
inline constexpr const char* kTwoBodiesMsh = R"($MeshFormat
2.2 0 8
$EndMeshFormat
$Nodes
9
1 0 0 0
2 1 0 0
3 0 1 0
4 0 0 1
5 0.1 0.1 0.1
6 2 0 0
7 0 2 0
8 0 0 2
9 7 7 7
$EndNodes
$Elements
2
1 4 2 6 60 5 6 7 8
2 4 2 5 50 1 2 3 4
$EndElements
)";

} // namespace tethash::test
