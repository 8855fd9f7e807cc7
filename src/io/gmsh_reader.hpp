#pragma once
// Private to tethash::io: the Gmsh .msh reader, shared by its parts: gmsh_read.cpp (format header, section
// loop, checks shared by both versions, the mesh), gmsh_read41.cpp (4.1: entities, node and element blocks)
// and gmsh_read22.cpp (2.2: nodes, elements).
//
// Reading keeps the 4-node tets (element type 4) in file order and all nodes in file order; other
// element types are skipped with a count in ReadNotes. Labels: 4.1 -> the first physical tag of the
// tet block's entity (from $Entities) if it has one, else the entity tag; 2.2 -> the first (physical)
// tag of the element, or the second (elementary) tag where the physical tag is 0 or absent.
#include "tethash/io/mesh_io.hpp"

#include "text_reader.hpp"

#include <algorithm>
#include <array>
#include <cstdint>
#include <limits>
#include <map>
#include <string>
#include <string_view>
#include <unordered_map>
#include <vector>

namespace tethash::io::detail {

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

inline constexpr std::int64_t k_max_int32 = std::numeric_limits<std::int32_t>::max();
inline constexpr std::int64_t k_max_count = std::numeric_limits<std::int64_t>::max() / 2;

class MshReader {
  public:
    MshReader(const std::string& path, ReadNotes* notes, const ReadOptions& options)
        : m_r(path), m_notes(notes), m_options(options)
    {
    }

    TetMesh read();

  private:
    bool binary() const { return m_binary; }

    void read_format();

    // ---- small readers that work in both modes -------------------------------------------
    std::int64_t read_size(std::string_view what);
    std::int64_t read_int(std::string_view what);
    std::int64_t read_tag(std::string_view what) { return m_version == 41 ? read_size(what) : read_int(what); }

    /// Checks that `count` items fit in what is left of the file: `bytes_each` bytes each in a binary
    /// file, `values_each` numbers each in an ASCII one (at least a byte each: the loose bound leaves a
    /// merely truncated file to the reader's precise message). Division only, so that no declared count
    /// overflows; products of `count` are then safe and loops over it bounded.
    void check_room(std::int64_t count, std::size_t bytes_each, std::size_t values_each, const std::string& what);

    /// One coordinate of node `tag`.
    double read_coord(std::int64_t tag, int axis);

    /// Fails unless the blocks of section $`section` held the `total` `items` its header announced (at the
    /// byte offset in a binary file, else at the line of the token that follows).
    /// Fails unless a block's `count` fits in what the section header leaves, total − seen: block `block`
    /// (0-based) of the `kind` blocks ("node" or "element") of section $`section`.
    void check_block_count(std::int64_t count, std::int64_t seen, std::int64_t total, std::int64_t block,
                           const std::string& kind, const std::string& section);
    void check_blocks_total(std::int64_t seen, std::int64_t total, std::int64_t blocks, const std::string& items,
                            const std::string& section);
    void expect_end(std::string_view marker);

    /// Builds the node map once all nodes are read (a node tag given twice is an error).
    void finish_nodes();
    /// 0-based index of node `node_tag`; an error naming element `element_tag` if absent (`at`: its byte offset).
    Index node_index(std::int64_t node_tag, std::int64_t element_tag, std::size_t at);
    void skip_elements(std::int64_t type, std::int64_t count) { m_skipped[type] += count; }
    /// 4-node tets, and 10-node tets (type 11) when linearizing.
    bool is_tet(std::int64_t type) const { return type == 4 || (type == 11 && m_options.linearize); }
    /// The mesh from what was read.
    TetMesh finish();

    // ---- 4.1 (gmsh_read41.cpp) ------------------------------------------------------------------
    void read_entities41();
    void read_nodes41();
    void read_elements41();

    /// Label of a tet in entity (dim, tag) of a 4.1 file: the first physical tag, else the entity tag.
    std::int64_t label_of(std::int64_t dim, std::int64_t entity) const;

    // ---- 2.2 (gmsh_read22.cpp) ------------------------------------------------------------------
    void read_nodes22();
    void read_element22(std::int64_t type, std::int64_t ntags, std::int64_t etag);
    void read_elements22();

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

} // namespace tethash::io::detail
