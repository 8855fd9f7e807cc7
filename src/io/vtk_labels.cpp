// Object ids and labels as VTK data arrays (see vtk_labels.hpp).
#include "vtk_labels.hpp"

#include "number.hpp"
#include "tethash/error.hpp"

#include <algorithm>
#include <cmath>

namespace tethash::io::vtk_detail {

using detail::to_lower;

namespace {
const char* const k_object_names[] = {"object", "tet_object", "vertex_object"};
const char* const k_cell_label_names[] = {"tet_label",     "label",       "gmsh:physical", "medit:ref",
                                          "cellentityids", "materialids", "material"};
const char* const k_point_label_names[] = {"vertex_label", "label", "medit:ref", "tetgen:ref"};

/// Rank of `name` in `list` (lower is preferred), or -1.
template <std::size_t N> int rank_in(const std::string& name, const char* const (&list)[N])
{
    for (std::size_t i = 0; i < N; ++i)
        if (name == list[i]) return static_cast<int>(i);
    return -1;
}

bool all_integers(const std::vector<double>& v, double min_value)
{
    return std::all_of(v.begin(), v.end(), [&](double x) {
        return std::isfinite(x) && x == std::floor(x) && x >= min_value && x <= 2147483647.0;
    });
}
} // namespace

bool is_label_array_name(std::string_view name, bool cell)
{
    const std::string n = to_lower(name);
    if (rank_in(n, k_object_names) >= 0) return true;
    return cell ? rank_in(n, k_cell_label_names) >= 0 : rank_in(n, k_point_label_names) >= 0;
}

void apply_label_arrays(TetMesh& mesh, const std::vector<NamedArray>& point_arrays,
                        const std::vector<NamedArray>& cell_arrays, const std::vector<std::int64_t>& tet_cells,
                        std::size_t num_cells_in_file, ReadNotes* notes)
{
    const auto note = [&](const std::string& s) {
        if (notes) notes->messages.push_back(s);
    };
    const std::size_t n = static_cast<std::size_t>(mesh.num_vertices());
    // Picks the best-ranked usable array of a list.
    const auto pick = [&](const std::vector<NamedArray>& arrays, const auto& names, double min_value,
                          std::size_t expected, const char* what) -> const NamedArray* {
        const NamedArray* best = nullptr;
        int best_rank = 1 << 30;
        for (const NamedArray& a : arrays) {
            const int r = rank_in(to_lower(a.name), names);
            if (r < 0 || r >= best_rank) continue;
            if (a.values.size() != expected) {
                note(a.where + ": array '" + a.name + "' has " + std::to_string(a.values.size()) +
                     " values, expected " + std::to_string(expected) + "; not used as " + what);
                continue;
            }
            if (!all_integers(a.values, min_value)) {
                note(a.where + ": array '" + a.name + "' holds values that are not " +
                     (min_value >= 0 ? "non-negative " : "") + "integers; not used as " + what);
                continue;
            }
            best = &a;
            best_rank = r;
        }
        return best;
    };
    const auto per_tet = [&](const NamedArray& a) {
        std::vector<Index> r(tet_cells.size());
        for (std::size_t t = 0; t < tet_cells.size(); ++t)
            r[t] = static_cast<Index>(a.values[static_cast<std::size_t>(tet_cells[t])]);
        return r;
    };
    // Object ids number objects from 0 and every object holds at least one cell or point, so an id
    // must be below their count: larger ones (2147483647) would overflow the object count.
    const auto check_object_ids = [&](const NamedArray& a, const char* element) {
        for (std::size_t i = 0; i < a.values.size(); ++i)
            if (a.values[i] >= static_cast<double>(a.values.size()))
                throw Error(a.where + ": array '" + a.name + "' gives " + element + " " + std::to_string(i) +
                            " object id " + std::to_string(static_cast<std::int64_t>(a.values[i])) +
                            ", expected an id below the number of " + element + "s (" +
                            std::to_string(a.values.size()) + "): objects are numbered from 0");
    };
    const std::size_t cells = num_cells_in_file;
    if (const NamedArray* a = pick(cell_arrays, k_object_names, 0, cells, "object ids")) {
        check_object_ids(*a, "cell");
        mesh.tet_object = per_tet(*a);
    }
    if (const NamedArray* a = pick(cell_arrays, k_cell_label_names, -2147483648.0, cells, "tet labels"))
        mesh.tet_label = per_tet(*a);
    if (const NamedArray* a = pick(point_arrays, k_object_names, 0, n, "object ids")) {
        check_object_ids(*a, "point");
        mesh.vertex_object.assign(a->values.begin(), a->values.end());
    }
    if (const NamedArray* a = pick(point_arrays, k_point_label_names, -2147483648.0, n, "vertex labels"))
        mesh.vertex_label.assign(a->values.begin(), a->values.end());

    // Object ids on one side only: derive the other (a vertex takes the object of a tet using it).
    if (!mesh.tet_object.empty() && mesh.vertex_object.empty()) {
        mesh.vertex_object.assign(n, 0);
        for (Index t = 0; t < mesh.num_tets(); ++t)
            for (int k = 0; k < 4; ++k)
                mesh.vertex_object[static_cast<std::size_t>(mesh.tets(t, k))] = mesh.tet_object[t];
    } else if (mesh.tet_object.empty() && !mesh.vertex_object.empty()) {
        mesh.tet_object.resize(static_cast<std::size_t>(mesh.num_tets()));
        for (Index t = 0; t < mesh.num_tets(); ++t)
            mesh.tet_object[t] = mesh.vertex_object[static_cast<std::size_t>(mesh.tets(t, 0))];
    }
}

void collect_out_arrays(const std::string& path, const TetMesh& mesh, const Fields& fields, bool allow_spaces,
                        std::vector<OutArray>& point, std::vector<OutArray>& cell)
{
    point.clear();
    cell.clear();
    const auto check = [&](const Field& f, std::size_t count, const char* where) {
        if (f.name.empty()) throw Error(path + ": a " + std::string(where) + " field has an empty name");
        for (unsigned char c : f.name) {
            if (c < 32 || c == 127 || (!allow_spaces && c == ' '))
                throw Error(path + ": " + where + " field name '" + f.name + "' contains " +
                            (c == ' ' ? "a space, which legacy .vtk cannot store" : "a control character"));
            if (c == '"' || c == '<' || c == '&')
                throw Error(path + ": " + where + " field name '" + f.name + "' contains '" +
                            std::string(1, static_cast<char>(c)) + "'");
        }
        if (f.components < 1)
            throw Error(path + ": " + where + " field '" + f.name + "' has " + std::to_string(f.components) +
                        " components, expected at least 1");
        if (f.values.size() != count * static_cast<std::size_t>(f.components))
            throw Error(path + ": " + where + " field '" + f.name + "' has " + std::to_string(f.values.size()) +
                        " values, expected " + std::to_string(count) + " × " + std::to_string(f.components) + " = " +
                        std::to_string(count * static_cast<std::size_t>(f.components)));
    };
    const auto add_fields = [&](const std::vector<Field>& in, std::size_t count, const char* where,
                                std::vector<OutArray>& out) {
        for (const Field& f : in) {
            check(f, count, where);
            for (const OutArray& o : out)
                if (o.name == f.name)
                    throw Error(path + ": two " + std::string(where) + " fields are called '" + f.name + "'");
            out.push_back({f.name, f.components, false, &f.values, nullptr});
        }
    };
    const std::size_t n = static_cast<std::size_t>(mesh.num_vertices()), m = static_cast<std::size_t>(mesh.num_tets());
    add_fields(fields.point, n, "point", point);
    add_fields(fields.cell, m, "cell", cell);
    const auto add_ints = [](std::vector<OutArray>& out, const char* name, const std::vector<Index>& v,
                             std::size_t count) {
        if (v.size() != count || count == 0) return;
        for (const OutArray& o : out)
            if (o.name == name) return; // a user field of that name wins
        out.push_back({name, 1, true, nullptr, &v});
    };
    add_ints(point, "object", mesh.vertex_object, n);
    add_ints(point, "vertex_label", mesh.vertex_label, n);
    add_ints(cell, "object", mesh.tet_object, m);
    add_ints(cell, "tet_label", mesh.tet_label, m);
    for (Index i = 0; i < mesh.num_vertices(); ++i)
        for (int k = 0; k < 3; ++k)
            if (!std::isfinite(mesh.positions(i, k)))
                throw Error(path + ": point " + std::to_string(i) + " has a non-finite coordinate; not writing it");
}

} // namespace tethash::io::vtk_detail
