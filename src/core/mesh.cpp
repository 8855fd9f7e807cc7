#include "tethash/mesh.hpp"

#include "tethash/error.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <string>

namespace tethash {

namespace {

std::array<Index, 4> tet_at(const TetsRef& tets, Index t)
{
    return {tets(t, 0), tets(t, 1), tets(t, 2), tets(t, 3)};
}

/// The four faces of a tet (a,b,c,d), each oriented outward when the tet is positively oriented.
constexpr int kFace[4][3] = {{1, 2, 3}, {0, 3, 2}, {0, 1, 3}, {0, 2, 1}};

struct FaceKey {
    std::array<Index, 3> sorted;
    std::int64_t slot; ///< tet * 4 + local face
    bool operator<(const FaceKey& o) const { return sorted < o.sorted || (sorted == o.sorted && slot < o.slot); }
};

std::vector<FaceKey> sorted_faces(const TetsRef& tets)
{
    std::vector<FaceKey> faces;
    faces.reserve(static_cast<std::size_t>(tets.rows()) * 4);
    for (Index t = 0; t < tets.rows(); ++t)
        for (int f = 0; f < 4; ++f) {
            std::array<Index, 3> k = {tets(t, kFace[f][0]), tets(t, kFace[f][1]), tets(t, kFace[f][2])};
            std::sort(k.begin(), k.end());
            faces.push_back({k, std::int64_t(t) * 4 + f});
        }
    std::sort(faces.begin(), faces.end());
    return faces;
}

Eigen::Vector3d row(const PositionsRef& p, Index i)
{
    return p.row(i).transpose();
}

} // namespace

Index TetMesh::num_objects() const
{
    if (positions.rows() == 0 && tets.rows() == 0) return 0;
    Index mx = 0;
    for (Index o : vertex_object)
        mx = std::max(mx, o);
    for (Index o : tet_object)
        mx = std::max(mx, o);
    return mx + 1;
}

void TetMesh::ensure_object_ids()
{
    if (vertex_object.empty()) vertex_object.assign(static_cast<std::size_t>(positions.rows()), 0);
    if (tet_object.empty()) tet_object.assign(static_cast<std::size_t>(tets.rows()), 0);
}

void TetMesh::append(const TetMesh& other)
{
    const Index offset_v = num_vertices();
    const Index offset_o = num_objects();
    ensure_object_ids();
    const bool had_rest = rest_positions.rows() != 0 || other.rest_positions.rows() != 0;
    Positions rest_a = rest();
    const Positions& rest_b = other.rest();

    Positions p(positions.rows() + other.positions.rows(), 3);
    p << positions, other.positions;
    positions.swap(p);
    if (had_rest) {
        Positions r(rest_a.rows() + rest_b.rows(), 3);
        r << rest_a, rest_b;
        rest_positions.swap(r);
    }
    Tets t(tets.rows() + other.tets.rows(), 4);
    t.topRows(tets.rows()) = tets;
    t.bottomRows(other.tets.rows()) = other.tets.array() + offset_v;
    tets.swap(t);

    for (Index i = 0; i < other.num_vertices(); ++i)
        vertex_object.push_back(offset_o + (other.vertex_object.empty() ? 0 : other.vertex_object[i]));
    for (Index i = 0; i < other.num_tets(); ++i)
        tet_object.push_back(offset_o + (other.tet_object.empty() ? 0 : other.tet_object[i]));

    const bool labels_t = !tet_label.empty() || !other.tet_label.empty();
    if (labels_t) {
        tet_label.resize(static_cast<std::size_t>(tets.rows() - other.tets.rows()), 0);
        for (Index i = 0; i < other.num_tets(); ++i)
            tet_label.push_back(other.tet_label.empty() ? 0 : other.tet_label[i]);
    }
    const bool labels_v = !vertex_label.empty() || !other.vertex_label.empty();
    if (labels_v) {
        vertex_label.resize(static_cast<std::size_t>(offset_v), 0);
        for (Index i = 0; i < other.num_vertices(); ++i)
            vertex_label.push_back(other.vertex_label.empty() ? 0 : other.vertex_label[i]);
    }
}

LabelSplit split_objects_by_label(TetMesh& mesh, SharedLabelVertices shared, const std::string& what)
{
    mesh.check_consistency(what);
    const Index n = mesh.num_vertices(), m = mesh.num_tets();
    LabelSplit out;
    if (mesh.tet_label.empty()) {
        mesh.vertex_object.assign(static_cast<std::size_t>(n), 0);
        mesh.tet_object.assign(static_cast<std::size_t>(m), 0);
        if (n > 0 || m > 0) out.object_labels.push_back({});
        return out;
    }
    // Distinct labels in increasing order; each tet's label as an index into them.
    std::vector<Index> labels(mesh.tet_label);
    std::sort(labels.begin(), labels.end());
    labels.erase(std::unique(labels.begin(), labels.end()), labels.end());
    const auto k = labels.size();
    auto label_index = [&](Index label) {
        return static_cast<std::size_t>(std::lower_bound(labels.begin(), labels.end(), label) - labels.begin());
    };
    // Union-find over label indices (used by join only); a vertex records the first label seen.
    std::vector<std::size_t> parent(k);
    for (std::size_t i = 0; i < k; ++i)
        parent[i] = i;
    auto find = [&](std::size_t i) {
        while (parent[i] != i)
            i = parent[i] = parent[parent[i]];
        return i;
    };
    constexpr std::size_t none = static_cast<std::size_t>(-1);
    std::vector<std::size_t> vertex_label(static_cast<std::size_t>(n), none);
    std::vector<char> vertex_shared(static_cast<std::size_t>(n), 0);
    for (Index t = 0; t < m; ++t) {
        const std::size_t li = label_index(mesh.tet_label[static_cast<std::size_t>(t)]);
        for (int c = 0; c < 4; ++c) {
            const auto v = static_cast<std::size_t>(mesh.tets(t, c));
            if (vertex_label[v] == none) {
                vertex_label[v] = li;
            } else if (vertex_label[v] != li) {
                if (shared == SharedLabelVertices::error)
                    throw Error(what + ": vertex " + std::to_string(v) + " is in tets of label " +
                                std::to_string(labels[vertex_label[v]]) + " and of label " +
                                std::to_string(labels[li]) + " (tet " + std::to_string(t) +
                                "): these labels are not separate bodies");
                vertex_shared[v] = 1;
                const std::size_t a = find(vertex_label[v]), b = find(li);
                if (a != b) parent[std::max(a, b)] = std::min(a, b);
            }
        }
    }
    for (char c : vertex_shared)
        out.shared_vertices += c;
    // Objects numbered by their smallest label (roots are the smallest index of their set).
    std::vector<Index> object_of_root(k, -1);
    for (std::size_t i = 0; i < k; ++i) {
        const std::size_t r = find(i);
        if (object_of_root[r] < 0) {
            object_of_root[r] = static_cast<Index>(out.object_labels.size());
            out.object_labels.emplace_back();
        }
        out.object_labels[static_cast<std::size_t>(object_of_root[r])].push_back(labels[i]);
    }
    mesh.tet_object.resize(static_cast<std::size_t>(m));
    for (Index t = 0; t < m; ++t)
        mesh.tet_object[static_cast<std::size_t>(t)] =
            object_of_root[find(label_index(mesh.tet_label[static_cast<std::size_t>(t)]))];
    mesh.vertex_object.resize(static_cast<std::size_t>(n));
    for (Index v = 0; v < n; ++v) {
        const std::size_t li = vertex_label[static_cast<std::size_t>(v)];
        mesh.vertex_object[static_cast<std::size_t>(v)] = li == none ? 0 : object_of_root[find(li)];
    }
    return out;
}

void TetMesh::check_consistency(const std::string& what) const
{
    const auto n = positions.rows();
    const auto m = tets.rows();
    if (rest_positions.rows() != 0 && rest_positions.rows() != n)
        throw Error(what + ": " + std::to_string(rest_positions.rows()) + " rest positions for " + std::to_string(n) +
                    " vertices");
    auto check_size = [&](const std::vector<Index>& v, Eigen::Index expect, const char* name) {
        if (!v.empty() && static_cast<Eigen::Index>(v.size()) != expect)
            throw Error(what + ": " + name + " has " + std::to_string(v.size()) + " entries, expected " +
                        std::to_string(expect));
    };
    check_size(vertex_object, n, "vertex_object");
    check_size(tet_object, m, "tet_object");
    check_size(tet_label, m, "tet_label");
    check_size(vertex_label, n, "vertex_label");
    for (Index t = 0; t < m; ++t)
        for (int k = 0; k < 4; ++k) {
            const Index v = tets(t, k);
            if (v < 0 || v >= n)
                throw Error(what + ": tet " + std::to_string(t) + " refers to vertex " + std::to_string(v) +
                            ", but there are " + std::to_string(n) + " vertices (valid: 0.." + std::to_string(n - 1) +
                            ")");
        }
    for (std::size_t i = 0; i < vertex_object.size(); ++i)
        if (vertex_object[i] < 0)
            throw Error(what + ": vertex " + std::to_string(i) + " has negative object id " +
                        std::to_string(vertex_object[i]));
    for (std::size_t i = 0; i < tet_object.size(); ++i)
        if (tet_object[i] < 0)
            throw Error(what + ": tet " + std::to_string(i) + " has negative object id " +
                        std::to_string(tet_object[i]));
}

double signed_volume(const PositionsRef& p, const std::array<Index, 4>& t)
{
    const Eigen::Vector3d a = row(p, t[0]);
    return (row(p, t[1]) - a).dot((row(p, t[2]) - a).cross(row(p, t[3]) - a)) / 6.0;
}

namespace {
/// Degenerate: |volume| tiny relative to the cube of the longest edge (zero volume up to rounding).
bool is_degenerate(const PositionsRef& p, const std::array<Index, 4>& t, double vol)
{
    double longest = 0;
    for (int i = 0; i < 4; ++i)
        for (int j = i + 1; j < 4; ++j)
            longest = std::max(longest, (row(p, t[i]) - row(p, t[j])).norm());
    return std::abs(vol) <= 1e-12 * longest * longest * longest;
}
} // namespace

bool ValidationReport::ok() const
{
    return index_out_of_range == 0 && repeated_index == 0 && non_finite == 0;
}

std::vector<std::string> ValidationReport::problems() const
{
    std::vector<std::string> out;
    auto add = [&](std::int64_t n, const char* what) {
        if (n) out.push_back(std::to_string(n) + " " + what);
    };
    add(index_out_of_range, "tets with a vertex index out of range");
    add(repeated_index, "tets with a repeated vertex");
    add(non_finite, "vertices with a non-finite coordinate");
    add(degenerate_tets, "degenerate (zero-volume) tets");
    add(inverted_tets, "inverted tets (negative volume; tethash convert --reorient flips them)");
    add(unreferenced_vertices, "unreferenced vertices");
    add(non_manifold_faces, "non-manifold faces (shared by more than two tets)");
    return out;
}

ValidationReport validate(const TetMesh& mesh)
{
    ValidationReport r;
    const Index n = mesh.num_vertices(), m = mesh.num_tets();
    auto note_tet = [&](Index t) {
        if (r.first_bad_tets.size() < 10 && (r.first_bad_tets.empty() || r.first_bad_tets.back() != t))
            r.first_bad_tets.push_back(t);
    };
    auto note_vertex = [&](Index v) {
        if (r.first_bad_vertices.size() < 10) r.first_bad_vertices.push_back(v);
    };
    std::vector<char> finite(static_cast<std::size_t>(n), 1);
    for (Index v = 0; v < n; ++v)
        if (!mesh.positions.row(v).allFinite()) {
            ++r.non_finite;
            finite[v] = 0;
            note_vertex(v);
        }
    std::vector<char> used(static_cast<std::size_t>(n), 0);
    std::vector<Index> good_tets;
    good_tets.reserve(static_cast<std::size_t>(m));
    for (Index t = 0; t < m; ++t) {
        const auto tet = tet_at(mesh.tets, t);
        bool range_ok = true;
        for (Index v : tet)
            if (v < 0 || v >= n) range_ok = false;
        if (!range_ok) {
            ++r.index_out_of_range;
            note_tet(t);
            continue;
        }
        for (Index v : tet)
            used[v] = 1;
        bool repeated = false;
        for (int i = 0; i < 4; ++i)
            for (int j = i + 1; j < 4; ++j)
                repeated |= tet[i] == tet[j];
        if (repeated) {
            ++r.repeated_index;
            note_tet(t);
            continue;
        }
        if (!(finite[tet[0]] && finite[tet[1]] && finite[tet[2]] && finite[tet[3]])) continue;
        good_tets.push_back(t);
        const double vol = signed_volume(mesh.positions, tet);
        if (is_degenerate(mesh.positions, tet, vol)) {
            ++r.degenerate_tets;
            note_tet(t);
        } else if (vol < 0) {
            ++r.inverted_tets;
            note_tet(t);
        }
    }
    for (Index v = 0; v < n; ++v)
        if (!used[v]) {
            ++r.unreferenced_vertices;
            note_vertex(v);
        }
    // Non-manifold faces among the tets whose indices are valid.
    Tets valid(static_cast<Eigen::Index>(good_tets.size()), 4);
    for (std::size_t i = 0; i < good_tets.size(); ++i)
        valid.row(static_cast<Eigen::Index>(i)) = mesh.tets.row(good_tets[i]);
    const auto faces = sorted_faces(valid);
    for (std::size_t i = 0; i < faces.size();) {
        std::size_t j = i;
        while (j < faces.size() && faces[j].sorted == faces[i].sorted)
            ++j;
        if (j - i > 2) {
            ++r.non_manifold_faces;
            note_tet(good_tets[static_cast<std::size_t>(faces[i].slot / 4)]);
        }
        i = j;
    }
    return r;
}

std::int64_t reorient_inverted(TetMesh& mesh)
{
    std::int64_t count = 0;
    const Index n = mesh.num_vertices();
    for (Index t = 0; t < mesh.num_tets(); ++t) {
        const auto tet = tet_at(mesh.tets, t);
        bool ok = true;
        for (Index v : tet)
            ok &= v >= 0 && v < n;
        if (!ok) continue;
        const double vol = signed_volume(mesh.positions, tet);
        if (vol < 0 && !is_degenerate(mesh.positions, tet, vol)) {
            std::swap(mesh.tets(t, 2), mesh.tets(t, 3));
            ++count;
        }
    }
    return count;
}

Edges unique_edges(const TetsRef& tets)
{
    std::vector<std::pair<Index, Index>> e;
    e.reserve(static_cast<std::size_t>(tets.rows()) * 6);
    for (Index t = 0; t < tets.rows(); ++t)
        for (int i = 0; i < 4; ++i)
            for (int j = i + 1; j < 4; ++j) {
                Index a = tets(t, i), b = tets(t, j);
                if (a == b) continue;
                if (a > b) std::swap(a, b);
                e.emplace_back(a, b);
            }
    std::sort(e.begin(), e.end());
    e.erase(std::unique(e.begin(), e.end()), e.end());
    Edges out(static_cast<Eigen::Index>(e.size()), 2);
    for (std::size_t i = 0; i < e.size(); ++i) {
        out(static_cast<Eigen::Index>(i), 0) = e[i].first;
        out(static_cast<Eigen::Index>(i), 1) = e[i].second;
    }
    return out;
}

Triangles boundary_faces(const TetsRef& tets)
{
    const auto faces = sorted_faces(tets);
    std::vector<std::int64_t> boundary;
    for (std::size_t i = 0; i < faces.size();) {
        std::size_t j = i;
        while (j < faces.size() && faces[j].sorted == faces[i].sorted)
            ++j;
        if (j - i == 1) boundary.push_back(faces[i].slot);
        i = j;
    }
    std::sort(boundary.begin(), boundary.end()); // tet order: deterministic and local
    Triangles out(static_cast<Eigen::Index>(boundary.size()), 3);
    for (std::size_t i = 0; i < boundary.size(); ++i) {
        const Index t = static_cast<Index>(boundary[i] / 4);
        const int f = static_cast<int>(boundary[i] % 4);
        for (int k = 0; k < 3; ++k)
            out(static_cast<Eigen::Index>(i), k) = tets(t, kFace[f][k]);
    }
    return out;
}

namespace {
Adjacency build_csr(Index n, std::vector<std::pair<Index, Index>>& pairs)
{
    std::sort(pairs.begin(), pairs.end());
    pairs.erase(std::unique(pairs.begin(), pairs.end()), pairs.end());
    Adjacency a;
    a.offsets.assign(static_cast<std::size_t>(n) + 1, 0);
    for (const auto& [u, v] : pairs)
        ++a.offsets[static_cast<std::size_t>(u) + 1];
    for (Index i = 0; i < n; ++i)
        a.offsets[i + 1] += a.offsets[i];
    a.neighbours.reserve(pairs.size());
    for (const auto& p : pairs)
        a.neighbours.push_back(p.second);
    return a;
}
} // namespace

Adjacency vertex_adjacency(const TetsRef& tets, Index num_vertices)
{
    std::vector<std::pair<Index, Index>> pairs;
    pairs.reserve(static_cast<std::size_t>(tets.rows()) * 12);
    for (Index t = 0; t < tets.rows(); ++t)
        for (int i = 0; i < 4; ++i)
            for (int j = 0; j < 4; ++j)
                if (i != j && tets(t, i) != tets(t, j)) pairs.emplace_back(tets(t, i), tets(t, j));
    return build_csr(num_vertices, pairs);
}

Adjacency vertex_tets(const TetsRef& tets, Index num_vertices)
{
    std::vector<std::pair<Index, Index>> pairs;
    pairs.reserve(static_cast<std::size_t>(tets.rows()) * 4);
    for (Index t = 0; t < tets.rows(); ++t)
        for (int i = 0; i < 4; ++i)
            pairs.emplace_back(tets(t, i), t);
    return build_csr(num_vertices, pairs);
}

EdgeStats edge_stats(const PositionsRef& positions, const TetsRef& tets)
{
    const Edges e = unique_edges(tets);
    EdgeStats s;
    s.count = e.rows();
    if (e.rows() == 0) return s;
    s.min = std::numeric_limits<double>::infinity();
    double sum = 0;
    for (Eigen::Index i = 0; i < e.rows(); ++i) {
        const double len = (positions.row(e(i, 0)) - positions.row(e(i, 1))).norm();
        s.min = std::min(s.min, len);
        s.max = std::max(s.max, len);
        sum += len;
    }
    s.mean = sum / static_cast<double>(e.rows());
    return s;
}

VolumeStats volume_stats(const PositionsRef& positions, const TetsRef& tets)
{
    VolumeStats s;
    if (tets.rows() == 0) return s;
    s.min = std::numeric_limits<double>::infinity();
    s.max = -std::numeric_limits<double>::infinity();
    for (Index t = 0; t < tets.rows(); ++t) {
        const double v = signed_volume(positions, tet_at(tets, t));
        s.min = std::min(s.min, v);
        s.max = std::max(s.max, v);
        s.total += v;
    }
    s.mean = s.total / static_cast<double>(tets.rows());
    return s;
}

TetQuality tet_quality(const PositionsRef& p, const std::array<Index, 4>& t)
{
    TetQuality q;
    Eigen::Vector3d x[4];
    for (int i = 0; i < 4; ++i)
        x[i] = row(p, t[i]);
    // Outward face normals (for a positively oriented tet); face f is opposite vertex f.
    Eigen::Vector3d nrm[4];
    double area_sum = 0;
    for (int f = 0; f < 4; ++f) {
        const Eigen::Vector3d a = x[kFace[f][0]], b = x[kFace[f][1]], c = x[kFace[f][2]];
        nrm[f] = (b - a).cross(c - a);
        area_sum += 0.5 * nrm[f].norm();
    }
    const double vol = std::abs((x[1] - x[0]).dot((x[2] - x[0]).cross(x[3] - x[0]))) / 6.0;
    double longest = 0;
    q.min_dihedral_deg = 180;
    q.max_dihedral_deg = 0;
    for (int i = 0; i < 4; ++i)
        for (int j = i + 1; j < 4; ++j) {
            longest = std::max(longest, (x[i] - x[j]).norm());
            // The edge (i,j) is shared by the faces opposite the two other vertices k and l.
            int k = -1, l = -1;
            for (int v = 0; v < 4; ++v)
                if (v != i && v != j) (k < 0 ? k : l) = v;
            const double nk = nrm[k].norm(), nl = nrm[l].norm();
            double angle = 0;
            if (nk > 0 && nl > 0) {
                const double c = std::clamp(nrm[k].dot(nrm[l]) / (nk * nl), -1.0, 1.0);
                angle = 180.0 - std::acos(c) * 180.0 / std::numbers::pi;
            }
            q.min_dihedral_deg = std::min(q.min_dihedral_deg, angle);
            q.max_dihedral_deg = std::max(q.max_dihedral_deg, angle);
        }
    const double inradius = area_sum > 0 ? 3.0 * vol / area_sum : 0.0;
    q.aspect_ratio =
        inradius > 0 ? longest / (2.0 * std::sqrt(6.0) * inradius) : std::numeric_limits<double>::infinity();
    return q;
}

std::pair<Eigen::Vector3d, Eigen::Vector3d> bounding_box(const PositionsRef& positions)
{
    if (positions.rows() == 0) return {Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()};
    return {positions.colwise().minCoeff().transpose(), positions.colwise().maxCoeff().transpose()};
}

Index tet_components(const TetsRef& tets, Index num_vertices, std::vector<Index>* component)
{
    // Union-find over the vertices (path halving); a tet joins its four vertices.
    std::vector<Index> parent(static_cast<std::size_t>(std::max<Index>(num_vertices, 0)));
    for (Index v = 0; v < num_vertices; ++v)
        parent[static_cast<std::size_t>(v)] = v;
    const auto find = [&](Index v) {
        while (parent[static_cast<std::size_t>(v)] != v) {
            const Index up = parent[static_cast<std::size_t>(parent[static_cast<std::size_t>(v)])];
            parent[static_cast<std::size_t>(v)] = up;
            v = up;
        }
        return v;
    };
    for (Eigen::Index t = 0; t < tets.rows(); ++t)
        for (int k = 1; k < 4; ++k) {
            const Index a = find(tets(t, 0)), b = find(tets(t, k));
            if (a != b) parent[static_cast<std::size_t>(std::max(a, b))] = std::min(a, b);
        }
    std::vector<Index> id(parent.size(), -1);
    Index count = 0;
    if (component) component->resize(static_cast<std::size_t>(tets.rows()));
    for (Eigen::Index t = 0; t < tets.rows(); ++t) {
        Index& c = id[static_cast<std::size_t>(find(tets(t, 0)))];
        if (c < 0) c = count++;
        if (component) (*component)[static_cast<std::size_t>(t)] = c;
    }
    return count;
}

} // namespace tethash
