// Gmsh .msh 4.1 writer (ASCII and binary): one volume entity per tet label, nodes grouped by entity.
#include "tethash/io/file.hpp"
#include "tethash/io/gmsh.hpp"

#include "number.hpp"
#include "tethash/error.hpp"

#include <algorithm>
#include <array>
#include <cstring>
#include <map>
#include <utility>
#include <vector>

namespace tethash::io {

namespace {

/// Appends a value in the file's binary layout (native byte order) or as text followed by `sep`.
struct MshOut {
    bool binary;
    std::string s;
    void size(std::uint64_t v, char sep = ' ')
    {
        if (binary)
            raw(v);
        else {
            detail::append_int(s, static_cast<std::int64_t>(v));
            s += sep;
        }
    }
    void integer(std::int32_t v, char sep = ' ')
    {
        if (binary)
            raw(v);
        else {
            detail::append_int(s, v);
            s += sep;
        }
    }
    void real(double v, char sep = ' ')
    {
        if (binary)
            raw(v);
        else {
            detail::append_double(s, v);
            s += sep;
        }
    }
    template <class T> void raw(T v)
    {
        char b[sizeof(T)];
        std::memcpy(b, &v, sizeof(T));
        s.append(b, sizeof(T));
    }
    /// Header of a 4.1 $Nodes or $Elements section: number of blocks, of items, smallest and largest tag
    /// (items are tagged 1..count).
    void section_header(std::size_t blocks, std::uint64_t count)
    {
        size(blocks);
        size(count);
        size(count ? 1 : 0);
        size(count, '\n');
    }
    /// Header of a block of `count` items in volume entity `entity`: element type `type` (0 for nodes).
    void block_header(std::int32_t entity, std::int32_t type, std::size_t count)
    {
        integer(3);
        integer(entity);
        integer(type);
        size(count, '\n');
    }
    /// In binary, ends a binary run with the newline Gmsh puts before $End lines.
    void end_binary()
    {
        if (binary) s += '\n';
    }
};

} // namespace

void write_msh(const std::string& path, const TetMesh& mesh, bool binary)
{
    mesh.check_consistency("mesh to write to " + path);
    const Index n = mesh.num_vertices(), m = mesh.num_tets();
    const bool has_labels = static_cast<Index>(mesh.tet_label.size()) == m && m > 0;
    const bool has_objects = static_cast<Index>(mesh.tet_object.size()) == m && m > 0;

    // One volume entity per (object, label) pair, numbered 1.. in order of first appearance.
    std::map<std::pair<Index, Index>, Index> entity_of_key;
    std::vector<std::pair<Index, Index>> keys;
    std::vector<Index> tet_entity(static_cast<std::size_t>(m));
    for (Index t = 0; t < m; ++t) {
        const std::pair<Index, Index> key{has_objects ? mesh.tet_object[static_cast<std::size_t>(t)] : 0,
                                          has_labels ? mesh.tet_label[static_cast<std::size_t>(t)] : 0};
        auto [it, fresh] = entity_of_key.emplace(key, static_cast<Index>(keys.size()) + 1);
        if (fresh) keys.push_back(key);
        tet_entity[static_cast<std::size_t>(t)] = it->second;
    }
    if (keys.empty()) keys.push_back({0, 0}); // a mesh with no tets still needs an entity for its nodes
    const auto num_entities = static_cast<Index>(keys.size());

    // Nodes belong to the entity of the first tet that uses them (entity 1 if unused).
    std::vector<Index> node_entity(static_cast<std::size_t>(n), 0);
    for (Index t = 0; t < m; ++t)
        for (int k = 0; k < 4; ++k) {
            Index& e = node_entity[static_cast<std::size_t>(mesh.tets(t, k))];
            if (e == 0) e = tet_entity[static_cast<std::size_t>(t)];
        }
    for (Index& e : node_entity)
        if (e == 0) e = 1;

    // Bounding box per entity.
    std::vector<std::array<double, 6>> box(static_cast<std::size_t>(num_entities), {0, 0, 0, 0, 0, 0});
    std::vector<bool> box_set(static_cast<std::size_t>(num_entities), false);
    for (Index v = 0; v < n; ++v) {
        const auto e = static_cast<std::size_t>(node_entity[static_cast<std::size_t>(v)] - 1);
        for (int a = 0; a < 3; ++a) {
            const double x = mesh.positions(v, a);
            if (!box_set[e] || x < box[e][static_cast<std::size_t>(a)]) box[e][static_cast<std::size_t>(a)] = x;
            if (!box_set[e] || x > box[e][static_cast<std::size_t>(a) + 3]) box[e][static_cast<std::size_t>(a) + 3] = x;
        }
        box_set[e] = true;
    }

    // Runs of consecutive nodes / tets with the same entity become blocks (file order = index order).
    auto runs = [](const std::vector<Index>& entity) {
        std::vector<std::pair<std::size_t, std::size_t>> r; // [begin, end)
        for (std::size_t i = 0; i < entity.size();) {
            std::size_t j = i;
            while (j < entity.size() && entity[j] == entity[i])
                ++j;
            r.push_back({i, j});
            i = j;
        }
        return r;
    };
    const auto node_runs = runs(node_entity);
    const auto tet_runs = runs(tet_entity);

    MshOut o{binary, {}};
    o.s.reserve(static_cast<std::size_t>(n) * (binary ? 32 : 64) + static_cast<std::size_t>(m) * (binary ? 40 : 48) +
                1024);
    o.s += "$MeshFormat\n4.1 ";
    o.s += binary ? "1 8\n" : "0 8\n";
    if (binary) {
        o.raw(std::int32_t{1});
        o.s += '\n';
    }
    o.s += "$EndMeshFormat\n$Entities\n";
    o.size(0);
    o.size(0);
    o.size(0);
    o.size(static_cast<std::uint64_t>(num_entities), '\n');
    for (Index e = 0; e < num_entities; ++e) {
        o.integer(e + 1);
        for (int k = 0; k < 6; ++k)
            o.real(box[static_cast<std::size_t>(e)][static_cast<std::size_t>(k)]);
        if (has_labels) {
            o.size(1);
            o.integer(keys[static_cast<std::size_t>(e)].second);
        } else {
            o.size(0);
        }
        o.size(0, '\n'); // no bounding surfaces
    }
    o.end_binary();
    o.s += "$EndEntities\n$Nodes\n";
    o.section_header(node_runs.size(), static_cast<std::uint64_t>(n));
    for (const auto& [b, e] : node_runs) {
        o.block_header(node_entity[b], 0, e - b);
        for (std::size_t v = b; v < e; ++v)
            o.size(v + 1, '\n');
        for (std::size_t v = b; v < e; ++v) {
            const auto vi = static_cast<Index>(v);
            o.real(mesh.positions(vi, 0));
            o.real(mesh.positions(vi, 1));
            o.real(mesh.positions(vi, 2), '\n');
        }
    }
    o.end_binary();
    o.s += "$EndNodes\n$Elements\n";
    o.section_header(tet_runs.size(), static_cast<std::uint64_t>(m));
    for (const auto& [b, e] : tet_runs) {
        o.block_header(tet_entity[b], 4, e - b);
        for (std::size_t t = b; t < e; ++t) {
            const auto ti = static_cast<Index>(t);
            o.size(t + 1);
            for (int k = 0; k < 4; ++k)
                o.size(static_cast<std::uint64_t>(mesh.tets(ti, k)) + 1, k == 3 ? '\n' : ' ');
        }
    }
    o.end_binary();
    o.s += "$EndElements\n";
    write_text_file(path, o.s);
}

} // namespace tethash::io
