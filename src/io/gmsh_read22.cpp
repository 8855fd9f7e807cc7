// Gmsh .msh 2.2 reading (gmsh_reader.hpp): $Nodes and $Elements, labels from the element tags.
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

void MshReader::read_nodes22()
{
    const std::int64_t total = m_r.next_int_in("the number of nodes", 0, k_max_int32);
    m_r.skip_rest_of_line();
    check_room(total, 4 + 3 * sizeof(double), 4, "nodes");
    const auto reserve = static_cast<std::size_t>(std::min<std::int64_t>(total, m_r.size()));
    m_node_tags.reserve(reserve);
    m_xyz.reserve(3 * reserve);
    for (std::int64_t i = 0; i < total; ++i) {
        const std::int64_t tag = read_int("a node tag");
        for (int a = 0; a < 3; ++a)
            m_xyz.push_back(read_coord(tag, a));
        m_node_tags.push_back(tag);
    }
    expect_end("$EndNodes");
    finish_nodes();
}

void MshReader::read_element22(std::int64_t type, std::int64_t ntags, std::int64_t etag)
{
    std::int64_t physical = 0, elementary = 0;
    for (std::int64_t k = 0; k < ntags; ++k) {
        const std::int64_t t = read_int("a tag of element " + std::to_string(etag));
        if (k == 0) physical = t;
        if (k == 1) elementary = t;
    }
    const int nn = gmsh_nodes_per_element(type);
    if (is_tet(type)) {
        for (int k = 0; k < nn; ++k) { // a 10-node tet lists its corners first
            const std::size_t at = m_r.offset();
            const std::int64_t tag = read_int("a node tag of element " + std::to_string(etag));
            if (k < 4) m_tets.push_back(node_index(tag, etag, at));
        }
        m_labels.push_back(static_cast<Index>(physical != 0 ? physical : elementary));
        m_tet_tags.push_back(etag);
    } else {
        for (int k = 0; k < nn; ++k)
            read_int("a node tag of element " + std::to_string(etag));
        skip_elements(type, 1);
    }
}

void MshReader::read_elements22()
{
    const std::int64_t total = m_r.next_int_in("the number of elements", 0, k_max_count);
    m_r.skip_rest_of_line();
    if (!binary()) {
        check_room(total, 1, 3, "elements"); // a tag, a type and a number of tags at least
        for (std::int64_t e = 0; e < total; ++e) {
            const std::int64_t etag = m_r.next_int("an element tag");
            const std::int64_t type = m_r.next_int("the type of element " + std::to_string(etag));
            const std::int64_t ntags =
                m_r.next_int_in("the number of tags of element " + std::to_string(etag), 0, 1000);
            if (gmsh_nodes_per_element(type) == 0) {
                m_r.skip_rest_of_line(); // unknown type: an ASCII element is one line
                skip_elements(type, 1);
                continue;
            }
            read_element22(type, ntags, etag);
        }
    } else {
        std::int64_t seen = 0;
        while (seen < total) {
            const std::size_t at = m_r.offset();
            const std::int64_t type = read_int("an element type");
            const std::int64_t count = read_int("the number of elements that follow");
            const std::int64_t ntags = read_int("the number of tags");
            const int nn = gmsh_nodes_per_element(type);
            if (nn == 0)
                m_r.fail_at_byte(at, "element type " + std::to_string(type) +
                                         " is unknown, so its elements cannot be skipped in a binary file");
            if (count < 0 || count > total - seen)
                m_r.fail_at_byte(at + 4, "expected at most " + std::to_string(total - seen) +
                                             " elements in this group (the $Elements header says " +
                                             std::to_string(total) + " in all), found " + std::to_string(count));
            if (ntags < 0 || ntags > 1000)
                m_r.fail_at_byte(at + 8, "expected a number of tags 0..1000, found " + std::to_string(ntags));
            check_room(count, 4 * static_cast<std::size_t>(1 + ntags + nn), static_cast<std::size_t>(1 + ntags + nn),
                       "elements");
            for (std::int64_t e = 0; e < count; ++e) {
                const std::int64_t etag = read_int("an element tag");
                read_element22(type, ntags, etag);
            }
            seen += count;
        }
        // Some writers (meshio) add headers of empty groups after the last element.
        auto at_end_marker = [this] {
            std::string_view rest = m_r.rest();
            while (!rest.empty() && (rest.front() == '\n' || rest.front() == '\r'))
                rest.remove_prefix(1);
            return rest.rfind("$End", 0) == 0;
        };
        while (m_r.size() - m_r.offset() >= 12 && !at_end_marker()) {
            const std::size_t at = m_r.offset();
            read_int("an element type");
            const std::int64_t count = read_int("the number of elements that follow");
            read_int("the number of tags");
            if (count != 0)
                m_r.fail_at_byte(at, "expected $EndElements after " + std::to_string(total) +
                                         " elements (the $Elements header), found a group of " + std::to_string(count) +
                                         " more");
        }
    }
    expect_end("$EndElements");
}

} // namespace tethash::io::detail
