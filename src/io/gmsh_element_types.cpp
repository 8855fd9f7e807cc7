#include "gmsh_element_types.hpp"

#include <algorithm>
#include <iterator>

namespace tethash::io::detail {

namespace {

struct ElementType {
    std::int64_t type;
    int nodes;
    const char* name;
};

/// The element types of the Gmsh file format documentation that a mesh file may hold, by type number.
constexpr ElementType k_types[] = {
    {1, 2, "2-node line"},
    {2, 3, "3-node triangle"},
    {3, 4, "4-node quadrangle"},
    {4, 4, "4-node tetrahedron"},
    {5, 8, "8-node hexahedron"},
    {6, 6, "6-node prism"},
    {7, 5, "5-node pyramid"},
    {8, 3, "3-node line"},
    {9, 6, "6-node triangle"},
    {10, 9, "9-node quadrangle"},
    {11, 10, "10-node tetrahedron"},
    {12, 27, "27-node hexahedron"},
    {13, 18, "18-node prism"},
    {14, 14, "14-node pyramid"},
    {15, 1, "point"},
    {16, 8, "8-node quadrangle"},
    {17, 20, "20-node hexahedron"},
    {18, 15, "15-node prism"},
    {19, 13, "13-node pyramid"},
    {20, 9, "9-node incomplete triangle"},
    {21, 10, "10-node triangle"},
    {22, 12, "12-node incomplete triangle"},
    {23, 15, "15-node triangle"},
    {24, 15, "15-node incomplete triangle"},
    {25, 21, "21-node triangle"},
    {26, 4, "4-node line"},
    {27, 5, "5-node line"},
    {28, 6, "6-node line"},
    {29, 20, "20-node tetrahedron"},
    {30, 35, "35-node tetrahedron"},
    {31, 56, "56-node tetrahedron"},
    {92, 64, "64-node hexahedron"},
    {93, 125, "125-node hexahedron"},
};

const ElementType* find_type(std::int64_t type)
{
    const auto* it = std::lower_bound(std::begin(k_types), std::end(k_types), type,
                                      [](const ElementType& e, std::int64_t t) { return e.type < t; });
    return it != std::end(k_types) && it->type == type ? it : nullptr;
}

} // namespace

int gmsh_nodes_per_element(std::int64_t type)
{
    const ElementType* e = find_type(type);
    return e ? e->nodes : 0;
}

std::string gmsh_element_name(std::int64_t type)
{
    const ElementType* e = find_type(type);
    return e ? e->name : "unknown element";
}

} // namespace tethash::io::detail
