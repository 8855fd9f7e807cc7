// Gmsh .msh 4.1 reading (gmsh_reader.hpp): $Entities, node blocks, element blocks, labels by entity.
#include "gmsh_reader.hpp"

#include "gmsh_element_types.hpp"
#include "number.hpp"
#include "tethash/error.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <string>

namespace tethash::io::detail {

void MshReader::read_entities41()
{
    std::array<std::int64_t, 4> counts{};
    for (int d = 0; d < 4; ++d)
        counts[static_cast<std::size_t>(d)] = read_size("the number of entities of dimension " + std::to_string(d));
    for (int d = 0; d < 4; ++d) {
        for (std::int64_t i = 0; i < counts[static_cast<std::size_t>(d)]; ++i) {
            const std::int64_t tag = read_int("an entity tag");
            for (int k = 0; k < (d == 0 ? 3 : 6); ++k) {
                if (binary())
                    m_r.read_binary<double>("a bounding box value");
                else
                    m_r.next_double_any("a bounding box value of entity " + std::to_string(tag));
            }
            const std::int64_t nphys = read_size("the number of physical tags of entity " + std::to_string(tag));
            check_room(nphys, 4, 1, "physical tags");
            for (std::int64_t k = 0; k < nphys; ++k) {
                const std::int64_t p = read_int("a physical tag of entity " + std::to_string(tag));
                if (k == 0) m_entity_physical[d].emplace(tag, p);
            }
            if (d > 0) {
                const std::int64_t nb = read_size("the number of bounding entities of entity " + std::to_string(tag));
                check_room(nb, 4, 1, "bounding entity tags");
                for (std::int64_t k = 0; k < nb; ++k)
                    read_int("a bounding entity tag");
            }
        }
    }
    expect_end("$EndEntities");
}

void MshReader::read_nodes41()
{
    const std::int64_t blocks = read_size("the number of node blocks");
    const std::int64_t total = read_size("the number of nodes");
    read_size("the smallest node tag");
    read_size("the largest node tag");
    if (total > k_max_int32) m_r.fail("at most 2^31-1 nodes", std::to_string(total));
    check_room(total, 3 * sizeof(double) + m_size_t, 4, "nodes");
    const auto reserve = static_cast<std::size_t>(std::min<std::int64_t>(total, m_r.size()));
    m_node_tags.reserve(reserve);
    m_xyz.reserve(3 * reserve);
    std::int64_t seen = 0;
    std::vector<std::int64_t> block_tags;
    for (std::int64_t b = 0; b < blocks; ++b) {
        const std::int64_t dim =
            binary() ? read_int("an entity dimension") : m_r.next_int_in("an entity dimension", 0, 3);
        if (dim < 0 || dim > 3)
            m_r.fail_at_byte(m_r.offset() - 4, "expected an entity dimension 0..3, found " + std::to_string(dim));
        read_int("an entity tag");
        const std::int64_t parametric = read_int("the parametric flag (0 or 1)");
        if (parametric != 0 && parametric != 1) {
            if (binary())
                m_r.fail_at_byte(m_r.offset() - 4,
                                 "expected the parametric flag 0 or 1, found " + std::to_string(parametric));
            m_r.fail("the parametric flag 0 or 1", std::to_string(parametric));
        }
        const std::int64_t count = read_size("the number of nodes in the block");
        check_block_count(count, seen, total, b, "node", "Nodes");
        const int extra = parametric ? static_cast<int>(dim) : 0;
        check_room(count, m_size_t + (3 + static_cast<std::size_t>(extra)) * sizeof(double),
                   4 + static_cast<std::size_t>(extra), "nodes");
        block_tags.clear();
        for (std::int64_t i = 0; i < count; ++i)
            block_tags.push_back(read_size("a node tag"));
        for (std::int64_t i = 0; i < count; ++i) {
            const std::int64_t tag = block_tags[static_cast<std::size_t>(i)];
            for (int a = 0; a < 3; ++a)
                m_xyz.push_back(read_coord(tag, a));
            for (int a = 0; a < extra; ++a) {
                if (binary())
                    m_r.read_binary<double>("a parametric coordinate");
                else
                    m_r.next_double_any("a parametric coordinate of node " + std::to_string(tag));
            }
            m_node_tags.push_back(tag);
        }
        seen += count;
    }
    check_blocks_total(seen, total, blocks, "nodes", "Nodes");
    expect_end("$EndNodes");
    finish_nodes();
}

void MshReader::read_elements41()
{
    const std::int64_t blocks = read_size("the number of element blocks");
    const std::int64_t total = read_size("the number of elements");
    read_size("the smallest element tag");
    read_size("the largest element tag");
    std::int64_t seen = 0;
    for (std::int64_t b = 0; b < blocks; ++b) {
        const std::int64_t dim = read_int("an entity dimension");
        const std::int64_t entity = read_int("an entity tag");
        const std::size_t type_at = m_r.offset();
        const std::int64_t type = read_int("an element type");
        const std::int64_t count = read_size("the number of elements in the block");
        check_block_count(count, seen, total, b, "element", "Elements");
        const int nn = gmsh_nodes_per_element(type);
        if (is_tet(type)) {
            check_room(count, static_cast<std::size_t>(1 + nn) * m_size_t, static_cast<std::size_t>(1 + nn), "tets");
            const std::int64_t label = label_of(dim, entity);
            for (std::int64_t e = 0; e < count; ++e) {
                const std::int64_t etag = read_size("an element tag");
                for (int k = 0; k < nn; ++k) { // a 10-node tet lists its corners first
                    const std::size_t at = m_r.offset();
                    const std::int64_t tag = read_size("a node tag of element " + std::to_string(etag));
                    if (k < 4) m_tets.push_back(node_index(tag, etag, at));
                }
                m_labels.push_back(static_cast<Index>(label));
                m_tet_tags.push_back(etag);
            }
        } else if (nn > 0) {
            check_room(count, static_cast<std::size_t>(1 + nn) * m_size_t, static_cast<std::size_t>(1 + nn),
                       "elements");
            if (binary()) {
                m_r.skip_bytes(static_cast<std::size_t>(count) * static_cast<std::size_t>(1 + nn) * m_size_t,
                               "elements of type " + std::to_string(type));
            } else {
                for (std::int64_t e = 0; e < count * (1 + nn); ++e)
                    read_size("an element or node tag");
            }
            skip_elements(type, count);
        } else {
            if (binary())
                m_r.fail_at_byte(type_at, "element type " + std::to_string(type) +
                                              " is unknown, so its block cannot be skipped in a binary file");
            check_room(count, 1, 1, "element lines of type " + std::to_string(type));
            m_r.skip_rest_of_line();
            for (std::int64_t e = 0; e < count; ++e) {
                bool eof = false;
                m_r.next_line(&eof);
                if (eof) m_r.fail("element lines of type " + std::to_string(type), "end of file");
            }
            skip_elements(type, count);
        }
        seen += count;
    }
    check_blocks_total(seen, total, blocks, "elements", "Elements");
    expect_end("$EndElements");
}

std::int64_t MshReader::label_of(std::int64_t dim, std::int64_t entity) const
{
    if (dim >= 0 && dim <= 3) {
        const auto& m = m_entity_physical[static_cast<std::size_t>(dim)];
        const auto it = m.find(entity);
        if (it != m.end()) return it->second;
    }
    return entity;
}

} // namespace tethash::io::detail
