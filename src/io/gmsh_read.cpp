// Gmsh .msh 2.2 and 4.1 (ASCII and binary) reader.
//
// Reading keeps the 4-node tets (element type 4) in file order and all nodes in file order; other
// element types are skipped with a count in ReadNotes. Labels: 4.1 -> the first physical tag of the
// tet block's entity (from $Entities) if it has one, else the entity tag; 2.2 -> the first (physical)
// tag of the element, or the second (elementary) tag where the physical tag is 0 or absent.
#include "tethash/io/gmsh.hpp"

#include "gmsh_element_types.hpp"
#include "number.hpp"
#include "tethash/error.hpp"
#include "text_reader.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <limits>
#include <map>
#include <unordered_map>

namespace tethash::io {

namespace {

using detail::gmsh_element_name;
using detail::gmsh_nodes_per_element;
using detail::TextReader;

/// Node tag -> 0-based index, dense when the tags are compact, hashed otherwise.
class NodeMap {
  public:
    /// Builds the map; returns a tag that appears twice, or -1.
    std::int64_t build(const std::vector<std::int64_t>& tags)
    {
        m_dense.clear();
        m_sparse.clear();
        if (tags.empty()) return -1;
        const auto [mn, mx] = std::minmax_element(tags.begin(), tags.end());
        m_use_dense = *mn >= 0 && *mx <= 4 * static_cast<std::int64_t>(tags.size()) + 1024;
        if (m_use_dense) {
            m_dense.assign(static_cast<std::size_t>(*mx) + 1, -1);
            for (std::size_t i = 0; i < tags.size(); ++i) {
                Index& slot = m_dense[static_cast<std::size_t>(tags[i])];
                if (slot >= 0) return tags[i];
                slot = static_cast<Index>(i);
            }
        } else {
            m_sparse.reserve(tags.size());
            for (std::size_t i = 0; i < tags.size(); ++i)
                if (!m_sparse.emplace(tags[i], static_cast<Index>(i)).second) return tags[i];
        }
        return -1;
    }
    /// Index of `tag`, -1 if absent.
    Index find(std::int64_t tag) const
    {
        if (m_use_dense) {
            if (tag < 0 || tag >= static_cast<std::int64_t>(m_dense.size())) return -1;
            return m_dense[static_cast<std::size_t>(tag)];
        }
        const auto it = m_sparse.find(tag);
        return it == m_sparse.end() ? -1 : it->second;
    }

  private:
    bool m_use_dense = true;
    std::vector<Index> m_dense;
    std::unordered_map<std::int64_t, Index> m_sparse;
};

constexpr std::int64_t k_max_int32 = std::numeric_limits<std::int32_t>::max();
constexpr std::int64_t k_max_count = std::numeric_limits<std::int64_t>::max() / 2;

class MshReader {
  public:
    MshReader(const std::string& path, ReadNotes* notes, const ReadOptions& options)
        : m_r(path), m_notes(notes), m_options(options)
    {
    }

    TetMesh read()
    {
        m_r.expect("$MeshFormat");
        m_r.skip_rest_of_line();
        read_format();
        while (!m_r.at_end()) {
            const std::string_view tok = m_r.next("a section header");
            if (tok.front() != '$') m_r.fail("a section header such as $Nodes", TextReader::describe(tok));
            const std::string name(tok.substr(1));
            const std::int64_t header_line = m_r.line();
            m_r.skip_rest_of_line();
            if (name == "Nodes") {
                if (m_have_nodes) m_r.fail_message("a second $Nodes section (only one is supported)");
                if (m_version == 41)
                    read_nodes41();
                else
                    read_nodes22();
                m_have_nodes = true;
            } else if (name == "Elements") {
                if (!m_have_nodes) m_r.fail("$Nodes before $Elements", "$Elements");
                if (m_have_elements) m_r.fail_message("a second $Elements section (only one is supported)");
                if (m_version == 41)
                    read_elements41();
                else
                    read_elements22();
                m_have_elements = true;
            } else if (name == "Entities" && m_version == 41) {
                read_entities41();
            } else if (name == "MeshFormat") {
                m_r.fail_message("a second $MeshFormat section");
            } else if (name.rfind("End", 0) == 0) {
                m_r.fail("a section header", TextReader::describe(tok) + " (an end marker with no section open)");
            } else {
                // Unknown or unneeded sections ($PhysicalNames, $NodeData, $Periodic, $Surface, ...) are skipped.
                if (!m_r.skip_past_line("$End" + name))
                    m_r.fail_at_line(header_line, "section $" + name + " has no $End" + name + " line");
            }
        }
        if (!m_have_nodes) throw Error(m_r.path() + ": no $Nodes section");
        if (!m_have_elements) throw Error(m_r.path() + ": no $Elements section");
        return finish();
    }

  private:
    bool binary() const { return m_binary; }

    void read_format()
    {
        const std::string_view v = m_r.next("a version number");
        const std::string version(v);
        if (version == "4.1")
            m_version = 41;
        else if (version == "2.2" || version == "2.1" || version == "2.0" || version == "2")
            m_version = 22;
        else
            m_r.fail("MSH version 2.2 or 4.1", "version " + TextReader::describe(v));
        m_binary = m_r.next_int_in("file type (0 ASCII, 1 binary)", 0, 1) == 1;
        m_size_t = static_cast<std::size_t>(m_r.next_int_in("data size", 0, 64));
        if (m_version == 41 && m_size_t != 4 && m_size_t != 8)
            m_r.fail("data size 4 or 8 (bytes in a size_t)", std::to_string(m_size_t));
        if (m_version == 22 && m_size_t != 8) m_r.fail("data size 8 (bytes in a double)", std::to_string(m_size_t));
        m_r.skip_rest_of_line();
        if (m_binary) {
            const std::size_t at = m_r.offset();
            const auto one = m_r.read_binary<std::uint32_t>("the integer 1 (byte-order check)");
            if (one == 0x01000000u)
                m_r.set_swap_bytes(true);
            else if (one != 1u)
                m_r.fail_at_byte(at, "expected the integer 1 (byte-order check), found " + std::to_string(one));
        }
        m_r.expect("$EndMeshFormat");
        m_r.skip_rest_of_line();
    }

    // ---- small readers that work in both modes -------------------------------------------
    std::int64_t read_size(std::string_view what)
    {
        if (!binary()) return m_r.next_int_in(what, 0, k_max_count);
        const std::size_t at = m_r.offset();
        const std::uint64_t v = m_r.read_binary_uint(m_size_t, what);
        if (v > static_cast<std::uint64_t>(k_max_count))
            m_r.fail_at_byte(at, "expected " + std::string(what) + ", found " + std::to_string(v));
        return static_cast<std::int64_t>(v);
    }
    std::int64_t read_int(std::string_view what)
    {
        if (!binary()) return m_r.next_int_in(what, std::numeric_limits<std::int32_t>::min(), k_max_int32);
        return m_r.read_binary<std::int32_t>(what);
    }
    std::int64_t read_tag(std::string_view what) { return m_version == 41 ? read_size(what) : read_int(what); }

    /// Checks that `count` items fit in what is left of the file: `bytes_each` bytes each in a binary
    /// file, `values_each` numbers each in an ASCII one (at least a byte each: the loose bound leaves a
    /// merely truncated file to the reader's precise message). Division only, so that no declared count
    /// overflows; products of `count` are then safe and loops over it bounded.
    void check_room(std::int64_t count, std::size_t bytes_each, std::size_t values_each, const std::string& what)
    {
        const std::size_t left = m_r.size() - m_r.offset();
        if (count <= 0) return;
        if (binary()) {
            if (static_cast<std::uint64_t>(count) > left / bytes_each)
                m_r.fail_at_byte(m_r.offset(), "expected " + std::to_string(count) + " " + what + " (" +
                                                   std::to_string(static_cast<std::uint64_t>(count)) + " × " +
                                                   std::to_string(bytes_each) + " bytes), found end of file after " +
                                                   std::to_string(left) + " bytes");
            return;
        }
        if (static_cast<std::uint64_t>(count) > left / values_each)
            m_r.fail_message("expected " + std::to_string(count) + " " + what + " (" + std::to_string(values_each) +
                             " numbers each), but only " + std::to_string(left) +
                             " bytes remain in the file, too few to hold them");
    }

    /// One coordinate of node `tag`.
    double read_coord(std::int64_t tag, int axis)
    {
        static const char* names[] = {"x", "y", "z"};
        if (binary()) {
            const std::size_t at = m_r.offset();
            const double v = m_r.read_binary<double>("a coordinate");
            if (!std::isfinite(v))
                m_r.fail_at_byte(at, std::string("expected a finite ") + names[axis] + " coordinate of node " +
                                         std::to_string(tag) + ", found " + (std::isnan(v) ? "nan" : "inf"));
            return v;
        }
        if (m_r.peek().empty())
            m_r.next(std::string("the ") + names[axis] + " coordinate of node " + std::to_string(tag));
        const std::string_view tok = m_r.next("a coordinate");
        const auto v = detail::parse_double(tok);
        if (!v || !std::isfinite(*v))
            m_r.fail(std::string("a finite ") + names[axis] + " coordinate of node " + std::to_string(tag),
                     TextReader::describe(tok));
        return *v;
    }

    /// Fails unless the blocks of section $`section` held the `total` `items` its header announced (at the
    /// byte offset in a binary file, else at the line of the token that follows).
    void check_blocks_total(std::int64_t seen, std::int64_t total, std::int64_t blocks, const std::string& items,
                            const std::string& section)
    {
        if (seen == total) return;
        const std::string msg = "expected " + std::to_string(total) + " " + items + " (the $" + section +
                                " header), found " + std::to_string(seen) + " in its " + std::to_string(blocks) +
                                " blocks";
        if (binary()) m_r.fail_at_byte(m_r.offset(), msg);
        m_r.next("$End" + section);
        m_r.fail_message(msg);
    }
    void expect_end(std::string_view marker)
    {
        const std::string_view tok = m_r.peek();
        if (tok != marker) {
            if (binary())
                m_r.fail_at_byte(m_r.offset(), "expected " + std::string(marker) + ", found " +
                                                   TextReader::describe(tok.substr(0, 16)));
            m_r.next(marker);
            m_r.fail(marker, TextReader::describe(tok));
        }
        m_r.next(marker);
        m_r.skip_rest_of_line();
    }

    void finish_nodes()
    {
        const std::int64_t dup = m_map.build(m_node_tags);
        if (dup >= 0) m_r.fail_message("node tag " + std::to_string(dup) + " appears twice in $Nodes");
    }

    // ---- 4.1 -----------------------------------------------------------------------------------
    void read_entities41()
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
                    const std::int64_t nb =
                        read_size("the number of bounding entities of entity " + std::to_string(tag));
                    check_room(nb, 4, 1, "bounding entity tags");
                    for (std::int64_t k = 0; k < nb; ++k)
                        read_int("a bounding entity tag");
                }
            }
        }
        expect_end("$EndEntities");
    }

    void read_nodes41()
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
            if (count > total - seen) {
                const std::string msg = "expected at most " + std::to_string(total - seen) + " nodes in node block " +
                                        std::to_string(b + 1) + " (the $Nodes header says " + std::to_string(total) +
                                        " in all), found " + std::to_string(count);
                if (binary()) m_r.fail_at_byte(m_r.offset() - m_size_t, msg);
                m_r.fail_message(msg);
            }
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

    Index node_index(std::int64_t node_tag, std::int64_t element_tag, std::size_t at)
    {
        const Index i = m_map.find(node_tag);
        if (i < 0) {
            const std::string msg = "element " + std::to_string(element_tag) + ": node tag " +
                                    std::to_string(node_tag) + " is not in $Nodes (" +
                                    std::to_string(m_node_tags.size()) + " nodes)";
            if (binary()) m_r.fail_at_byte(at, msg);
            m_r.fail_message(msg);
        }
        return i;
    }

    void skip_elements(std::int64_t type, std::int64_t count) { m_skipped[type] += count; }
    /// 4-node tets, and 10-node tets (type 11) when linearizing.
    bool is_tet(std::int64_t type) const { return type == 4 || (type == 11 && m_options.linearize); }

    void read_elements41()
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
            if (count > total - seen) {
                const std::string msg = "expected at most " + std::to_string(total - seen) +
                                        " elements in element block " + std::to_string(b + 1) +
                                        " (the $Elements header says " + std::to_string(total) + " in all), found " +
                                        std::to_string(count);
                if (binary()) m_r.fail_at_byte(m_r.offset() - m_size_t, msg);
                m_r.fail_message(msg);
            }
            const int nn = gmsh_nodes_per_element(type);
            if (is_tet(type)) {
                check_room(count, static_cast<std::size_t>(1 + nn) * m_size_t, static_cast<std::size_t>(1 + nn),
                           "tets");
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

    /// Label of a tet in entity (dim, tag) of a 4.1 file: the first physical tag, else the entity tag.
    std::int64_t label_of(std::int64_t dim, std::int64_t entity) const
    {
        if (dim >= 0 && dim <= 3) {
            const auto& m = m_entity_physical[static_cast<std::size_t>(dim)];
            const auto it = m.find(entity);
            if (it != m.end()) return it->second;
        }
        return entity;
    }

    // ---- 2.2 -----------------------------------------------------------------------------------
    void read_nodes22()
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

    void read_element22(std::int64_t type, std::int64_t ntags, std::int64_t etag)
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

    void read_elements22()
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
                check_room(count, 4 * static_cast<std::size_t>(1 + ntags + nn),
                           static_cast<std::size_t>(1 + ntags + nn), "elements");
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
                                             " elements (the $Elements header), found a group of " +
                                             std::to_string(count) + " more");
            }
        }
        expect_end("$EndElements");
    }

    TetMesh finish()
    {
        TetMesh mesh;
        const auto n = static_cast<Index>(m_node_tags.size());
        mesh.positions.resize(n, 3);
        if (n) std::memcpy(mesh.positions.data(), m_xyz.data(), m_xyz.size() * sizeof(double));
        const auto m = static_cast<Index>(m_labels.size());
        mesh.tets.resize(m, 4);
        if (m) std::memcpy(mesh.tets.data(), m_tets.data(), m_tets.size() * sizeof(Index));
        mesh.tet_label = std::move(m_labels);
        if (m_notes) { // the file's own numbering: node and element tags
            m_notes->vertex_ids = m_node_tags;
            m_notes->tet_ids = std::move(m_tet_tags);
        }
        if (m_notes) {
            for (const auto& [type, count] : m_skipped) {
                m_notes->skipped_cells += count;
                m_notes->messages.push_back("skipped " + std::to_string(count) + " elements of type " +
                                            std::to_string(type) + " (" + gmsh_element_name(type) + ")");
                m_notes->skipped.push_back(
                    {count, "type " + std::to_string(type) + " (" + gmsh_element_name(type) + ")", type == 11});
            }
        }
        return mesh;
    }

    TextReader m_r;
    ReadNotes* m_notes;
    ReadOptions m_options;
    int m_version = 41;
    bool m_binary = false;
    std::size_t m_size_t = 8;
    bool m_have_nodes = false, m_have_elements = false;
    std::vector<std::int64_t> m_node_tags;
    std::vector<std::int64_t> m_tet_tags; ///< element tag of each tet
    std::vector<double> m_xyz;
    NodeMap m_map;
    std::vector<Index> m_tets;
    std::vector<Index> m_labels;
    std::array<std::map<std::int64_t, std::int64_t>, 4> m_entity_physical;
    std::map<std::int64_t, std::int64_t> m_skipped;
};

} // namespace

TetMesh read_msh(const std::string& path, ReadNotes* notes, const ReadOptions& options)
{
    MshReader reader(path, notes, options);
    return reader.read();
}

} // namespace tethash::io
