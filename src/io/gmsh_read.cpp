// Gmsh .msh reader (gmsh_reader.hpp): the format header, the section loop, checks shared by 2.2 and 4.1,
// the mesh; read_msh.
#include "gmsh_reader.hpp"

#include "gmsh_element_types.hpp"
#include "number.hpp"
#include "tethash/error.hpp"
#include "tethash/io/gmsh.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <string>

namespace tethash::io::detail {

TetMesh MshReader::read()
{
    m_r.expect("$MeshFormat");
    m_r.skip_rest_of_line();
    read_format();
    // A section that may stand once, read by the reader of the file's version.
    const auto read_once = [this](bool& done, const std::string& section, void (MshReader::*read41)(),
                                  void (MshReader::*read22)()) {
        if (done) m_r.fail_message("a second $" + section + " section (only one is supported)");
        (this->*(m_version == 41 ? read41 : read22))();
        done = true;
    };
    while (!m_r.at_end()) {
        const std::string_view tok = m_r.next("a section header");
        if (tok.front() != '$') m_r.fail("a section header such as $Nodes", TextReader::describe(tok));
        const std::string name(tok.substr(1));
        const std::int64_t header_line = m_r.line();
        m_r.skip_rest_of_line();
        if (name == "Nodes") {
            read_once(m_have_nodes, name, &MshReader::read_nodes41, &MshReader::read_nodes22);
        } else if (name == "Elements") {
            if (!m_have_nodes) m_r.fail("$Nodes before $Elements", "$Elements");
            read_once(m_have_elements, name, &MshReader::read_elements41, &MshReader::read_elements22);
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

void MshReader::read_format()
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

std::int64_t MshReader::read_size(std::string_view what)
{
    if (!binary()) return m_r.next_int_in(what, 0, k_max_count);
    const std::size_t at = m_r.offset();
    const std::uint64_t v = m_r.read_binary_uint(m_size_t, what);
    if (v > static_cast<std::uint64_t>(k_max_count))
        m_r.fail_at_byte(at, "expected " + std::string(what) + ", found " + std::to_string(v));
    return static_cast<std::int64_t>(v);
}

std::int64_t MshReader::read_int(std::string_view what)
{
    if (!binary()) return m_r.next_int_in(what, std::numeric_limits<std::int32_t>::min(), k_max_int32);
    return m_r.read_binary<std::int32_t>(what);
}

void MshReader::check_room(std::int64_t count, std::size_t bytes_each, std::size_t values_each, const std::string& what)
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

double MshReader::read_coord(std::int64_t tag, int axis)
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
    if (m_r.peek().empty()) m_r.next(std::string("the ") + names[axis] + " coordinate of node " + std::to_string(tag));
    const std::string_view tok = m_r.next("a coordinate");
    const auto v = detail::parse_double(tok);
    if (!v || !std::isfinite(*v))
        m_r.fail(std::string("a finite ") + names[axis] + " coordinate of node " + std::to_string(tag),
                 TextReader::describe(tok));
    return *v;
}

void MshReader::check_block_count(std::int64_t count, std::int64_t seen, std::int64_t total, std::int64_t block,
                                  const std::string& kind, const std::string& section)
{
    if (count <= total - seen) return;
    const std::string msg = "expected at most " + std::to_string(total - seen) + " " + kind + "s in " + kind +
                            " block " + std::to_string(block + 1) + " (the $" + section + " header says " +
                            std::to_string(total) + " in all), found " + std::to_string(count);
    if (binary()) m_r.fail_at_byte(m_r.offset() - m_size_t, msg);
    m_r.fail_message(msg);
}

void MshReader::check_blocks_total(std::int64_t seen, std::int64_t total, std::int64_t blocks, const std::string& items,
                                   const std::string& section)
{
    if (seen == total) return;
    const std::string msg = "expected " + std::to_string(total) + " " + items + " (the $" + section +
                            " header), found " + std::to_string(seen) + " in its " + std::to_string(blocks) + " blocks";
    if (binary()) m_r.fail_at_byte(m_r.offset(), msg);
    m_r.next("$End" + section);
    m_r.fail_message(msg);
}

void MshReader::expect_end(std::string_view marker)
{
    const std::string_view tok = m_r.peek();
    if (tok != marker) {
        if (binary())
            m_r.fail_at_byte(m_r.offset(),
                             "expected " + std::string(marker) + ", found " + TextReader::describe(tok.substr(0, 16)));
        m_r.next(marker);
        m_r.fail(marker, TextReader::describe(tok));
    }
    m_r.next(marker);
    m_r.skip_rest_of_line();
}

void MshReader::finish_nodes()
{
    const std::int64_t dup = m_map.build(m_node_tags);
    if (dup >= 0) m_r.fail_message("node tag " + std::to_string(dup) + " appears twice in $Nodes");
}

Index MshReader::node_index(std::int64_t node_tag, std::int64_t element_tag, std::size_t at)
{
    const Index i = m_map.find(node_tag);
    if (i < 0) {
        const std::string msg = "element " + std::to_string(element_tag) + ": node tag " + std::to_string(node_tag) +
                                " is not in $Nodes (" + std::to_string(m_node_tags.size()) + " nodes)";
        if (binary()) m_r.fail_at_byte(at, msg);
        m_r.fail_message(msg);
    }
    return i;
}

TetMesh MshReader::finish()
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

} // namespace tethash::io::detail

namespace tethash::io {

TetMesh read_msh(const std::string& path, ReadNotes* notes, const ReadOptions& options)
{
    detail::MshReader reader(path, notes, options);
    return reader.read();
}

} // namespace tethash::io
