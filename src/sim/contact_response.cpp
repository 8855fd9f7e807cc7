#include "contact_response.hpp"
#include "thread_choice.hpp"

#include "core/timing.hpp"

#include "tethash/detect_grammar.hpp"

#include <algorithm>
#include <cmath>

namespace tethash::sim {

namespace {

using Vec3 = Eigen::Vector3d;
using Mat3 = Eigen::Matrix3d;
using tethash::detail::Clock;
using tethash::detail::ms_since;

/// Closest points of segments p0 p1 and q0 q1: p0 + s (p1 − p0) and q0 + u (q1 − q0), s, u in [0, 1].
void closest_points(const Vec3& p0, const Vec3& p1, const Vec3& q0, const Vec3& q1, double& s, double& u)
{
    const Vec3 d1 = p1 - p0, d2 = q1 - q0, r = p0 - q0;
    const double a = d1.squaredNorm(), e = d2.squaredNorm(), f = d2.dot(r);
    s = 0;
    u = 0;
    if (!(a > 0) && !(e > 0)) return;
    if (!(a > 0)) {
        u = std::clamp(f / e, 0.0, 1.0);
        return;
    }
    const double c = d1.dot(r);
    if (!(e > 0)) {
        s = std::clamp(-c / a, 0.0, 1.0);
        return;
    }
    const double b = d1.dot(d2), denom = a * e - b * b;
    // Parallel segments (denom 0): any s; 0, then u and s clamped in turn.
    s = denom > 0 ? std::clamp((b * f - c * e) / denom, 0.0, 1.0) : 0.0;
    u = (b * s + f) / e;
    if (u < 0) {
        u = 0;
        s = std::clamp(-c / a, 0.0, 1.0);
    } else if (u > 1) {
        u = 1;
        s = std::clamp((b - c) / a, 0.0, 1.0);
    }
}

/// The edge-face contacts' skin (candidate reuse between substeps), in mean edges of the smallest moving object: on
/// the hand at 1/240 a quarter edge cost less than half or one edge (docs/simulator.md, "Edges through faces").
constexpr double edge_skin_edges = 0.25;

/// The threads of the stages that take every core where the scene says 0 (chosen step by step: the detector follows
/// the step's count, these run on every core).
int stage_threads(int threads)
{
    return threads > 0 ? threads : detail::ThreadChoice::every_core();
}

/// Whether some vertex of a[0..na) and some vertex of b[0..nb) lie nearer than `reach` in the rest state: the
/// contacts' locality rule (a self pair within it is the material's to resolve, not a contact).
bool near_at_rest(const Positions& rest, const Index* a, int na, const Index* b, int nb, double reach)
{
    for (int i = 0; i < na; ++i)
        for (int k = 0; k < nb; ++k)
            if ((rest.row(a[i]) - rest.row(b[k])).squaredNorm() < reach * reach) return true;
    return false;
}

} // namespace

void ContactResponse::setup(const Scene& scene, const TetMesh& mesh, const Model& model,
                            const std::vector<ObjectOptions>& options, const SceneObstacles* obstacles)
{
    m_obstacles = obstacles && obstacles->size() > 0 ? obstacles : nullptr;
    const size_t num_obstacles = m_obstacles ? static_cast<size_t>(m_obstacles->size()) : 0;
    m_mesh = &mesh;
    m_model = &model;
    // The positions the run starts from: `mesh` is the live state (its positions change every step and it keeps
    // no separate rest positions unless its file had them), so the rest state the local-contact test measures
    // in is copied here once.
    m_rest = mesh.rest();
    m_params = scene.contact;
    m_mu = scene.contact.friction;
    m_object_rate.assign(scene.objects.size() + num_obstacles, 0.0); // obstacles: static
    for (size_t o = 0; o < model.object_frequency_sq.size() && o < m_object_rate.size(); ++o)
        m_object_rate[o] = contact_rate_factor * model.object_frequency_sq[o];
    int dynamic_objects = 0;
    bool self = false;
    for (const ObjectSpec& o : scene.objects) {
        dynamic_objects += o.is_static ? 0 : 1;
        self = self || (!o.is_static && o.self_collision);
    }
    m_enabled = dynamic_objects > 0 && (self || scene.objects.size() >= 2 || num_obstacles > 0);
    if (m_enabled) {
        DetectParams params = scene.detect;
        if (!scene.table_size_of_vertices.empty())
            params.table_size = parse_table_size(scene.table_size_of_vertices, mesh.num_vertices(),
                                                 scene.source + ": detector.table_size");
        m_detector.set_params(params);
        m_detector.set_topology(mesh, options);
        m_penetration.set_topology(mesh);
        if (scene.contact.margin > 0 || scene.contact.speculative)
            m_proximity.setup(mesh, m_rest, model, options, scene.contact.margin, scene.contact.speculative,
                              local_contact_edges);
        if (scene.contact.edges) {
            m_edges.set_topology(mesh.tets, mesh.num_vertices(), mesh.vertex_object, mesh.tet_object, options);
            // Candidate reuse between substeps (EdgeFaceDetector::set_skin): a skin of edge_skin_edges × the
            // smallest moving object's mean edge.
            double edge = 0;
            for (size_t o = 0; o < model.object_mean_edge.size(); ++o)
                if (model.object_mean_edge[o] > 0 && (o >= options.size() || !options[o].is_static))
                    edge = edge > 0 ? std::min(edge, model.object_mean_edge[o]) : model.object_mean_edge[o];
            m_edges.set_skin(edge_skin_edges * edge);
            // The locality rule of the crossings (add_edge_contacts) applied in the find, so that neither the tests
            // nor the kept pairs hold the object's own neighbourhood; a hair narrower than the rule, so that rounding
            // never drops a pair the rule keeps. The crossings it leaves out are asked for one by one when a pair
            // needs them (crosses_locally).
            std::vector<double> reach(model.object_mean_edge.size());
            for (size_t o = 0; o < reach.size(); ++o)
                reach[o] = local_contact_edges * model.object_mean_edge[o] * (1 - 1e-9);
            m_edges.set_local_reach(m_rest, reach);
        }
        m_proximity.set_threads(stage_threads(scene.detect.threads));
        m_edge_threads = stage_threads(scene.detect.threads);
    }
}

void ContactResponse::set_threads(int threads)
{
    if (!m_enabled) return;
    m_detector.set_threads(threads);
    m_proximity.set_threads(stage_threads(threads));
    m_edge_threads = stage_threads(threads);
}

double ContactResponse::pair_stiffness(Index a, Index b, double m_eff) const
{
    // contact_rate_factor × the softer material's ω² × the contact's effective mass: the contact's own frequency
    // is a fixed multiple of the softer object's at its mean edge, whatever the two vertices weigh (a sliver's
    // light vertex gets a soft penalty, a heavy one a stiff one), so it adds a fixed share to every vertex's
    // stiffness-to-mass ratio and never sets the explicit limit. A static object takes its partner's.
    if (m_params.stiffness > 0) return m_params.stiffness;
    double ra = m_object_rate[static_cast<size_t>(a)], rb = m_object_rate[static_cast<size_t>(b)];
    if (!(ra > 0)) ra = rb;
    if (!(rb > 0)) rb = ra;
    return std::min(ra, rb) * m_eff;
}

void ContactResponse::update(const Positions& x, const Positions& v, double h, StepStats& stats)
{
    m_contacts.clear();
    m_near.clear();
    m_active.clear();
    m_weight.clear();
    m_k.clear();
    m_c.clear();
    m_mred.clear();
    m_edge_pairs.clear();
    m_released.clear();
    m_ignored_local = 0;
    if (!m_enabled) return;
    auto t0 = Clock::now();
    const std::vector<Contact>& found = m_detector.detect(x);
    stats.ms_detect += ms_since(t0);

    t0 = Clock::now();
    const TetMesh& mesh = *m_mesh;
    const Model& model = *m_model;
    const Positions& rest = m_rest;
    m_contacts.reserve(found.size());
    for (const Contact& c : found) {
        if (c.vertex_object == c.tet_object) {
            const double reach = local_contact_edges * model.object_mean_edge[static_cast<size_t>(c.tet_object)];
            const Index corners[4] = {mesh.tets(c.tet, 0), mesh.tets(c.tet, 1), mesh.tets(c.tet, 2),
                                      mesh.tets(c.tet, 3)};
            if (near_at_rest(rest, &c.vertex, 1, corners, 4, reach)) {
                ++m_ignored_local;
                continue;
            }
        }
        m_contacts.push_back(c);
    }
    stats.ms_response += ms_since(t0);

    t0 = Clock::now();
    m_penetration.compute(x, m_contacts);
    stats.ms_depth += ms_since(t0);
    if (m_proximity.enabled()) {
        t0 = Clock::now();
        m_proximity.update(x, v, h, m_contacts, m_near);
        stats.ms_proximity += ms_since(t0);
        stats.near_contacts = static_cast<std::int64_t>(m_near.size());
    }
    if (m_obstacles) { // inside test, depth and direction together
        t0 = Clock::now();
        m_obstacles->add_contacts(x, model.fixed, model.vertex_object, m_contacts);
        stats.ms_detect += ms_since(t0);
    }

    t0 = Clock::now();
    // The response's contacts: penetrated vertices pushed by their depth plus the margin, then the margin ones.
    m_active.reserve(m_contacts.size() + m_near.size());
    for (const Contact& c : m_contacts) {
        m_active.push_back(c);
        if (c.tet >= 0 && c.depth > 0) m_active.back().depth += m_proximity.margin(c.vertex); // 0 without margin
    }
    m_active.insert(m_active.end(), m_near.begin(), m_near.end());
    stats.ms_response += ms_since(t0);
    if (m_params.edges) {
        t0 = Clock::now();
        const EdgeFaceResult& crossings = m_edges.find(x, m_edge_threads);
        add_edge_contacts(crossings, x);
        stats.ms_detect += ms_since(t0);
        stats.edge_contacts = static_cast<std::int64_t>(m_edge_pairs.size());
    }

    t0 = Clock::now();
    const std::vector<Contact>& active = m_active;
    const size_t nc = active.size();
    const size_t edge_begin = nc - m_edge_pairs.size();
    m_k.resize(nc);
    m_c.resize(nc);
    m_mred.resize(nc);
    m_weight.assign(nc, 1.0);
    for (size_t q = 0; q < nc; ++q) {
        const Contact& c = active[q];
        // Effective mass of the contact: 1 / (1/m_v + Σ b_j² / m_j), the mass the penalty's direction sees when
        // the tet's point is x = Σ b_j x_j (fixed vertices and obstacles: infinite mass); an edge contact's, 1 / Σ
        // coef_j² / m_j over its four ends.
        double inv = 0;
        if (q >= edge_begin) {
            Index node[5];
            double coef[5];
            stencil(q, node, coef);
            for (int k = 0; k < 5; ++k) {
                const size_t j = static_cast<size_t>(node[k]);
                if (!model.fixed[j]) inv += coef[k] * coef[k] / model.mass[j];
            }
        } else {
            inv = model.fixed[static_cast<size_t>(c.vertex)] ? 0.0 : 1.0 / model.mass[static_cast<size_t>(c.vertex)];
            for (int k = 0; k < 4 && c.tet >= 0; ++k) {
                const size_t j = static_cast<size_t>(mesh.tets(c.tet, k));
                if (!model.fixed[j]) inv += c.bary[k] * c.bary[k] / model.mass[j];
            }
        }
        m_mred[q] = inv > 0 ? 1.0 / inv : 0.0;
        m_k[q] = pair_stiffness(c.vertex_object, c.tet_object, m_mred[q]);
        m_c[q] = m_params.damping > 0 ? m_params.damping : std::sqrt(m_k[q] * m_mred[q]);
    }
    // Weight: a vertex inside k tets of one object (on shared faces) gets 1/k of the response from each.
    for (size_t a = 0; a < edge_begin;) {
        size_t b = a;
        while (b < edge_begin && active[b].vertex == active[a].vertex)
            ++b;
        for (size_t i = a; i < b; ++i) {
            int same = 0;
            for (size_t j = a; j < b; ++j)
                same += active[j].tet_object == active[i].tet_object ? 1 : 0;
            m_weight[i] = 1.0 / same;
        }
        a = b;
    }
    // The end of an edge pulled out of a part it pierces passes through that part: the part does not push it back.
    for (size_t q = 0; q < edge_begin && !m_released.empty(); ++q)
        if (std::binary_search(m_released.begin(), m_released.end(),
                               std::make_pair(active[q].vertex, active[q].tet_object)))
            m_weight[q] = 0;
    // An edge contact: 1 / the most pairs either of its edges is in. Each corner of an intersection curve has two
    // neighbours, so an edge is in two pairs on a closed curve; at full weight each it was pushed twice as hard as an
    // edge with one partner, and a vertex's contacts above are weighted so that it is not either.
    m_edge_count.clear();
    for (const EdgePair& e : m_edge_pairs) {
        if (e.through) continue; // in no pair: weight 1
        m_edge_count.emplace_back(e.a[0], e.a[1]);
        m_edge_count.emplace_back(e.b[0], e.b[1]);
    }
    std::sort(m_edge_count.begin(), m_edge_count.end());
    const auto pairs_of = [&](const Index* ends) {
        const auto range = std::equal_range(m_edge_count.begin(), m_edge_count.end(), std::make_pair(ends[0], ends[1]));
        return static_cast<double>(range.second - range.first);
    };
    for (size_t q = edge_begin; q < nc; ++q) {
        const EdgePair& e = m_edge_pairs[q - edge_begin];
        m_weight[q] = e.through ? 1.0 : 1.0 / std::max(pairs_of(e.a), pairs_of(e.b));
    }
    stats.ms_response += ms_since(t0);
}

void ContactResponse::add_edge_contacts(const EdgeFaceResult& found, const Positions& x)
{
    const Model& model = *m_model;
    const std::vector<EdgeFaceContact>& crossings = found.contacts; // sorted by (edge, face)
    const Edges& edges = found.edges;                               // (i < j), sorted
    const auto edge_index = [&](Index i, Index j) -> Index {
        if (i > j) std::swap(i, j);
        Index lo = 0, hi = static_cast<Index>(edges.rows());
        while (lo < hi) {
            const Index mid = lo + (hi - lo) / 2;
            if (edges(mid, 0) < i || (edges(mid, 0) == i && edges(mid, 1) < j))
                lo = mid + 1;
            else
                hi = mid;
        }
        return lo < edges.rows() && edges(lo, 0) == i && edges(lo, 1) == j ? lo : -1;
    };
    // Whether boundary edge g passes through a boundary face of `object`.
    const auto crosses_object = [&](Index g, Index object) {
        auto it = std::lower_bound(crossings.begin(), crossings.end(), g,
                                   [](const EdgeFaceContact& c, Index e) { return c.edge < e; });
        for (; it != crossings.end() && it->edge == g; ++it)
            if (it->face_object == object) return true;
        return m_edges.crosses_locally(g, object, x); // a crossing the find left out as local
    };
    const Positions& rest = m_rest;
    // A self crossing the rest state calls local (a vertex of the edge and one of the face within the contacts'
    // reach): the material's to resolve, not a contact.
    const auto local_self = [&](const EdgeFaceContact& c) {
        return c.edge_object == c.face_object &&
               near_at_rest(rest, c.edge_vertices, 2, c.face_vertices, 3,
                            local_contact_edges * model.object_mean_edge[static_cast<size_t>(c.face_object)]);
    };
    // The pairs (edge, an edge of a face it passes through that passes through the first edge's object), each
    // once, the lower edge index first: the crossings of the intersection of two surfaces, taken two by two.
    m_edge_keys.clear();
    for (const EdgeFaceContact& c : crossings) {
        if (local_self(c)) continue;
        for (int k = 0; k < 3; ++k) {
            const Index g = edge_index(c.face_vertices[k], c.face_vertices[(k + 1) % 3]);
            if (g < 0 || !crosses_object(g, c.edge_object)) continue;
            m_edge_keys.emplace_back(std::min(c.edge, g), std::max(c.edge, g));
        }
    }
    std::sort(m_edge_keys.begin(), m_edge_keys.end());
    m_edge_keys.erase(std::unique(m_edge_keys.begin(), m_edge_keys.end()), m_edge_keys.end());
    for (const auto& [ea, eb] : m_edge_keys) {
        EdgePair e{};
        for (int k = 0; k < 2; ++k) {
            e.a[k] = edges(ea, k);
            e.b[k] = edges(eb, k);
        }
        const Vec3 a0 = x.row(e.a[0]).transpose(), a1 = x.row(e.a[1]).transpose();
        const Vec3 b0 = x.row(e.b[0]).transpose(), b1 = x.row(e.b[1]).transpose();
        closest_points(a0, a1, b0, b1, e.s, e.u);
        const Vec3 gap = (b0 + e.u * (b1 - b0)) - (a0 + e.s * (a1 - a0));
        const double depth = gap.norm();
        const Index oa = model.vertex_object[static_cast<size_t>(e.a[0])];
        if (!(depth > 1e-12 * model.object_mean_edge[static_cast<size_t>(oa)])) continue; // met: no direction
        Contact ct;
        ct.vertex = e.s > 0.5 ? e.a[1] : e.a[0];
        ct.vertex_object = oa;
        ct.tet = -1;
        ct.tet_object = model.vertex_object[static_cast<size_t>(e.b[0])];
        ct.depth = depth;
        for (int r = 0; r < 3; ++r)
            ct.direction[r] = gap(r) / depth; // a towards b
        m_edge_pairs.push_back(e);
        m_active.push_back(ct);
    }
    // An edge in no pair that passes in through one face of a far part and out through another (a thin part pierced
    // straight through, the intersection curve inside one face of it, so no edge of that part crosses back): pushed
    // along itself the shorter way, until the crossings are beyond its nearer end; the face it leaves the part
    // through last on that way pushed back. Crossings of one edge are consecutive (sorted by edge, face).
    m_paired.clear();
    m_released.clear();
    for (const auto& [ea, eb] : m_edge_keys) {
        m_paired.push_back(ea);
        m_paired.push_back(eb);
    }
    std::sort(m_paired.begin(), m_paired.end());
    for (size_t i = 0; i < crossings.size();) {
        size_t j = i;
        while (j < crossings.size() && crossings[j].edge == crossings[i].edge)
            ++j;
        if (j - i >= 2 && !std::binary_search(m_paired.begin(), m_paired.end(), crossings[i].edge)) {
            for (size_t k = i; k < j; ++k) {
                const Index object = crossings[k].face_object;
                bool first = true; // the first crossing of this object: it makes the object's contact
                for (size_t m = i; m < k; ++m)
                    first = first && crossings[m].face_object != object;
                if (!first) continue;
                const EdgeFaceContact *lo = nullptr, *hi = nullptr; // its far crossings of least and greatest t
                for (size_t m = k; m < j; ++m) {
                    const EdgeFaceContact& c = crossings[m];
                    if (c.face_object != object || local_self(c)) continue;
                    if (!lo || c.edge_t < lo->edge_t) lo = &c;
                    if (!hi || c.edge_t > hi->edge_t) hi = &c;
                }
                // In through the first, out through the last (from end 0 to end 1).
                if (!lo || lo == hi || lo->inner_end != 1 || hi->inner_end != 0) continue;
                const Vec3 a0 = x.row(lo->edge_vertices[0]).transpose(), a1 = x.row(lo->edge_vertices[1]).transpose();
                const double length = (a1 - a0).norm();
                if (!(length > 0)) continue;
                const Vec3 along = (a1 - a0) / length;
                // Forwards (towards end 1) the part leaves past end 0 after hi's t × length; backwards past end 1 after
                // (1 − lo's t) × length.
                const bool forwards = hi->edge_t <= 1 - lo->edge_t;
                const EdgeFaceContact& c = forwards ? *hi : *lo;
                EdgePair e{};
                e.through = true;
                e.a[0] = e.b[0] = c.edge_vertices[0];
                e.a[1] = e.b[1] = c.edge_vertices[1];
                e.s = c.edge_t;
                for (int v = 0; v < 3; ++v) {
                    e.f[v] = c.face_vertices[v];
                    e.bary[v] = c.face_bary[v];
                }
                Contact ct;
                ct.vertex = forwards ? c.edge_vertices[0] : c.edge_vertices[1];
                ct.vertex_object = c.edge_object;
                ct.tet = -1;
                ct.tet_object = c.face_object;
                ct.depth = forwards ? c.edge_t * length : (1 - c.edge_t) * length;
                for (int r = 0; r < 3; ++r)
                    ct.direction[r] = forwards ? along(r) : -along(r);
                m_edge_pairs.push_back(e);
                m_active.push_back(ct);
                m_released.emplace_back(ct.vertex, ct.tet_object);
            }
        }
        i = j;
    }
    std::sort(m_released.begin(), m_released.end());
}

void ContactResponse::stencil(size_t q, Index node[5], double coef[5]) const
{
    const Contact& c = m_active[q];
    const size_t edge_begin = m_active.size() - m_edge_pairs.size();
    if (q >= edge_begin) {
        const EdgePair& e = m_edge_pairs[q - edge_begin];
        if (e.through) {
            node[0] = e.a[0];
            node[1] = e.a[1];
            coef[0] = 1.0 - e.s;
            coef[1] = e.s;
            for (int v = 0; v < 3; ++v) {
                node[2 + v] = e.f[v];
                coef[2 + v] = -e.bary[v];
            }
            return;
        }
        node[0] = e.a[0];
        node[1] = e.a[1];
        node[2] = e.b[0];
        node[3] = e.b[1];
        node[4] = e.a[0];
        coef[0] = 1.0 - e.s;
        coef[1] = e.s;
        coef[2] = -(1.0 - e.u);
        coef[3] = -e.u;
        coef[4] = 0.0;
        return;
    }
    node[0] = c.vertex;
    coef[0] = 1.0;
    if (c.tet < 0) { // an obstacle: fixed, only the vertex moves
        for (int k = 1; k < 5; ++k) {
            node[k] = c.vertex;
            coef[k] = 0.0;
        }
        return;
    }
    for (int k = 0; k < 4; ++k) {
        node[k + 1] = m_mesh->tets(c.tet, k);
        coef[k + 1] = -c.bary[k];
    }
}

template <class Visit> void ContactResponse::for_each_pushing(Visit&& visit) const
{
    for (size_t q = 0; q < m_active.size(); ++q) {
        const Contact& c = m_active[q];
        if (!(c.depth > 0)) continue;
        Index node[5];
        double coef[5];
        stencil(q, node, coef);
        visit(q, static_cast<const Index*>(node), static_cast<const double*>(coef),
              Vec3(c.direction[0], c.direction[1], c.direction[2]));
    }
}

void ContactResponse::add_forces(const Positions& vel, Positions& f, double h, bool cap) const
{
    for_each_pushing([&](size_t q, const Index* node, const double* coef, const Vec3& nrm) {
        const Contact& c = m_active[q];
        Vec3 vrel = Vec3::Zero();
        for (int a = 0; a < 5; ++a)
            vrel += coef[a] * vel.row(node[a]).transpose();
        const double vn = vrel.dot(nrm);
        const double w = m_weight[q];
        double scale = 1.0;
        if (cap && m_k[q] > 0) scale = std::min(1.0, 0.5 * m_mred[q] / (h * h * m_k[q]));
        const double fn = w * std::max(0.0, scale * (m_k[q] * c.depth - m_c[q] * vn));
        Vec3 force = fn * nrm;
        if (m_mu > 0 && fn > 0) {
            // Coulomb friction along the relative tangential velocity, smoothed below the vertex's object's
            // friction_speed and capped so that it cannot reverse the relative sliding in one step.
            const Vec3 vt = vrel - vn * nrm;
            const double speed = vt.norm();
            double ft = m_mu * fn * std::min(1.0, speed / m_model->friction_speed[static_cast<size_t>(c.vertex)]);
            if (h > 0 && m_mred[q] > 0) ft = std::min(ft, w * m_mred[q] * speed / h);
            if (speed > 0) force -= ft * vt / speed;
        }
        for (int a = 0; a < 5; ++a)
            f.row(node[a]) += coef[a] * force.transpose();
    });
}

template <class Visit> void ContactResponse::for_each_term(double scale_k, double scale_c, Visit&& visit) const
{
    for_each_pushing([&](size_t q, const Index* node, const double* coef, const Vec3& nrm) {
        visit(node, coef, nrm, m_weight[q] * (scale_k * m_k[q] + scale_c * m_c[q]));
    });
}

void ContactResponse::add_triplets(double scale_k, double scale_c, std::vector<Eigen::Triplet<double>>& out) const
{
    const std::vector<char>& fixed = m_model->fixed;
    for_each_term(scale_k, scale_c, [&](const Index* node, const double* coef, const Vec3& nrm, double s) {
        const Mat3 nn = s * nrm * nrm.transpose();
        for (int a = 0; a < 5; ++a) {
            if (fixed[static_cast<size_t>(node[a])]) continue;
            for (int b = 0; b < 5; ++b) {
                if (fixed[static_cast<size_t>(node[b])]) continue;
                const Mat3 blk = coef[a] * coef[b] * nn;
                for (int r = 0; r < 3; ++r)
                    for (int t = 0; t < 3; ++t)
                        if (blk(r, t) != 0) out.emplace_back(3 * node[a] + r, 3 * node[b] + t, blk(r, t));
            }
        }
    });
}

void ContactResponse::apply(double scale_k, double scale_c, const Eigen::VectorXd& p, Eigen::VectorXd& out) const
{
    const std::vector<char>& fixed = m_model->fixed;
    for_each_term(scale_k, scale_c, [&](const Index* node, const double* coef, const Vec3& nrm, double s) {
        double jp = 0;
        for (int a = 0; a < 5; ++a)
            if (!fixed[static_cast<size_t>(node[a])]) jp += coef[a] * nrm.dot(p.segment<3>(3 * node[a]));
        const Vec3 y = s * jp * nrm;
        for (int a = 0; a < 5; ++a)
            if (!fixed[static_cast<size_t>(node[a])]) out.segment<3>(3 * node[a]) += coef[a] * y;
    });
}

void ContactResponse::add_diagonal(double scale_k, double scale_c, Eigen::VectorXd& diag) const
{
    const std::vector<char>& fixed = m_model->fixed;
    for_each_term(scale_k, scale_c, [&](const Index* node, const double* coef, const Vec3& nrm, double s) {
        for (int a = 0; a < 5; ++a)
            if (!fixed[static_cast<size_t>(node[a])])
                diag.segment<3>(3 * node[a]) += coef[a] * coef[a] * s * nrm.cwiseProduct(nrm);
    });
}

double ContactResponse::energy() const
{
    double e = 0;
    for (size_t q = 0; q < m_active.size(); ++q)
        if (m_active[q].depth > 0) e += 0.5 * m_weight[q] * m_k[q] * m_active[q].depth * m_active[q].depth;
    return e;
}

double ContactResponse::max_depth() const
{
    double d = 0;
    for (const Contact& c : m_contacts)
        if (c.depth > d) d = c.depth;
    return d;
}

std::vector<double> ContactResponse::exact_depths(const Positions& x) const
{
    if (!m_enabled) return {};
    if (!m_obstacles) return m_penetration.exact_depths(x, m_contacts);
    std::vector<Contact> tets;
    for (const Contact& c : m_contacts)
        if (c.tet >= 0) tets.push_back(c);
    const std::vector<double> tet_depths = m_penetration.exact_depths(x, tets);
    std::vector<double> out;
    size_t next = 0;
    for (const Contact& c : m_contacts)
        out.push_back(c.tet >= 0 ? tet_depths[next++] : m_obstacles->exact_depth(x, c));
    return out;
}

} // namespace tethash::sim
