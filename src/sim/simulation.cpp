#include "tethash/sim/simulation.hpp"

#include "tethash/error.hpp"
#include "tethash/io/generate.hpp"
#include "tethash/io/surface.hpp"

#include <Eigen/Geometry>
#include <Eigen/SparseCholesky>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <sstream>

namespace tethash::sim {

namespace {

using Vec3 = Eigen::Vector3d;
using Mat3 = Eigen::Matrix3d;
using SpMat = Eigen::SparseMatrix<double>;
using Clock = std::chrono::steady_clock;

double ms_since(Clock::time_point t0)
{
    return std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
}

std::string num(double v)
{
    std::ostringstream s;
    s.precision(3);
    s << v;
    return s.str();
}

/// Loads or generates the mesh of one object (one object id, no labels), transformed.
TetMesh load_object(const ObjectSpec& o)
{
    TetMesh m;
    if (!o.mesh.empty()) {
        if (io::is_surface_path(o.mesh) && !io::is_tet_mesh_path(o.mesh)) {
            io::TetrahedralizeParams tp;
            tp.resolution = o.surface_resolution;
            m = io::tetrahedralize(io::read_surface(o.mesh), tp);
        } else {
            m = io::read_mesh(o.mesh);
        }
    } else if (o.generate) {
        m = io::generate(*o.generate);
    } else if (o.data) {
        m = *o.data;
    } else {
        throw Error("object '" + o.name + "': no mesh, generate or data");
    }
    m.check_consistency("object '" + o.name + "'");
    if (m.num_tets() == 0) throw Error("object '" + o.name + "': the mesh has no tets");
    m.vertex_object.clear();
    m.tet_object.clear();
    m.vertex_label.clear();
    m.tet_label.clear();
    const Mat3 rot = (Eigen::AngleAxisd(o.rotate_deg.z() * M_PI / 180, Vec3::UnitZ()) *
                      Eigen::AngleAxisd(o.rotate_deg.y() * M_PI / 180, Vec3::UnitY()) *
                      Eigen::AngleAxisd(o.rotate_deg.x() * M_PI / 180, Vec3::UnitX()))
                         .toRotationMatrix();
    auto apply = [&](Positions& p) {
        for (Index i = 0; i < p.rows(); ++i) {
            const Vec3 q = rot * (o.scale.cwiseProduct(p.row(i).transpose())) + o.translate;
            p.row(i) = q.transpose();
        }
    };
    apply(m.positions);
    if (m.rest_positions.rows()) apply(m.rest_positions);
    for (Index i = 0; i < m.num_vertices(); ++i)
        if (!m.positions.row(i).allFinite())
            throw Error("object '" + o.name + "': vertex " + std::to_string(i) + " is not finite");
    return m;
}

} // namespace

class SimulationImpl {
  public:
    Scene scene;
    TetMesh mesh; // positions = current x
    Positions v;
    Model model;
    std::vector<std::pair<Index, Index>> obj_vertices, obj_tets;
    std::vector<ObjectOptions> options;
    Detector detector;
    bool detect_enabled = false;
    Penetration penetration;
    std::vector<Contact> contacts;
    std::vector<double> contact_weight;                     // 1 / number of contacts of (vertex, object)
    std::vector<double> contact_k, contact_c, contact_mred; // per contact: stiffness, damping, reduced mass
    std::vector<double> object_k;                           // per object: stiffest spring (0 for static objects)
    double mu = 0;
    double msum = 0;        // total free mass
    Vec3 centre0{0, 0, 0};  // bounding box centre at start
    double radius0 = 0;     // half the bounding box diagonal at start
    double speed_bound = 0; // no vertex can reach this speed on the energy available at start
    StepStats stats;
    std::vector<std::string> warnings;
    std::int64_t steps_done = 0;
    double t = 0;
    double energy_ref = 0;
    double dt_limit = std::numeric_limits<double>::infinity();
    double min_free_mass = 0, mean_free_mass = 0;
    Model::Linearised lin; // implicit Euler (CG): operator cache, adjacency kept between steps
    // local/global
    double lg_h = -1;
    std::vector<Index> lg_free; // vertex → free index or −1
    Eigen::SimplicialLLT<SpMat> lg_solver;
    SpMat lg_matrix;
    double lg_vol_scale = 1;

    explicit SimulationImpl(const Scene& s);
    void detect_and_respond(double& ms_detect, double& ms_response);
    /// Penalty + friction forces of the contacts for a step h (friction capped so that it cannot reverse a
    /// relative sliding velocity within h). `cap`: each contact's stiffness and damping also capped at the
    /// explicit limit of h (local/global, where contacts are explicit).
    void add_contact_forces(const Positions& vel, Positions& f, double h, bool cap) const;
    double pair_stiffness(Index a, Index b) const;
    void contact_coefficients();
    void add_contact_triplets(double scale_k, double scale_c, std::vector<Eigen::Triplet<double>>& out) const;
    double contact_energy() const;
    void contact_apply(double scale_k, double scale_c, const Eigen::VectorXd& p, Eigen::VectorXd& out) const;
    void contact_diagonal(double scale_k, double scale_c, Eigen::VectorXd& diag) const;
    void substep_symplectic(double h);
    int substep_implicit(double h);
    void substep_local_global(double h);
    void setup_local_global(double h);
    bool state_finite() const;
    std::string check_state(double t_end) const;
    std::string likely_cause(double h) const;
};

SimulationImpl::SimulationImpl(const Scene& s) : scene(s)
{
    if (!(scene.dt > 0) || !std::isfinite(scene.dt)) throw Error("dt must be positive, found " + num(scene.dt));
    if (scene.substeps < 1) throw Error("substeps must be ≥ 1, found " + std::to_string(scene.substeps));
    if (scene.objects.empty()) throw Error(scene.source + ": the scene has no objects");
    std::vector<Material> materials;
    std::vector<char> is_static;
    for (size_t k = 0; k < scene.objects.size(); ++k) {
        const ObjectSpec& o = scene.objects[k];
        TetMesh m = load_object(o);
        const Index v0 = mesh.num_vertices(), t0 = mesh.num_tets();
        mesh.append(m);
        obj_vertices.emplace_back(v0, m.num_vertices());
        obj_tets.emplace_back(t0, m.num_tets());
        materials.push_back(o.material);
        is_static.push_back(o.is_static ? 1 : 0);
        ObjectOptions opt;
        opt.self_collision = o.self_collision;
        opt.is_static = o.is_static;
        options.push_back(opt);
    }
    mesh.ensure_object_ids();
    const Index n = mesh.num_vertices();
    model = Model::build(mesh, materials, is_static);
    model.gravity = scene.gravity;

    // Pins.
    for (size_t p = 0; p < scene.pins.size(); ++p) {
        const PinRegion& pin = scene.pins[p];
        Index first = 0, count = n;
        if (pin.object >= 0) {
            if (pin.object >= static_cast<int>(obj_vertices.size()))
                throw Error("pin " + std::to_string(p) + ": object " + std::to_string(pin.object) + " does not exist");
            first = obj_vertices[static_cast<size_t>(pin.object)].first;
            count = obj_vertices[static_cast<size_t>(pin.object)].second;
        }
        for (Index id : pin.vertices) {
            if (id < 0 || id >= count)
                throw Error("pin " + std::to_string(p) + ": vertex " + std::to_string(id) + " out of range (" +
                            std::to_string(count) + " vertices)");
            model.fixed[static_cast<size_t>(first + id)] = 1;
        }
        if (pin.has_box) {
            std::int64_t hit = 0;
            for (Index i = first; i < first + count; ++i) {
                const Vec3 q = mesh.positions.row(i).transpose();
                if ((q.array() >= pin.box_min.array()).all() && (q.array() <= pin.box_max.array()).all()) {
                    model.fixed[static_cast<size_t>(i)] = 1;
                    ++hit;
                }
            }
            if (hit == 0) warnings.push_back("pin " + std::to_string(p) + ": the box holds no vertex");
        }
    }

    // Velocities.
    v = Positions::Zero(n, 3);
    for (size_t k = 0; k < scene.objects.size(); ++k)
        for (Index i = obj_vertices[k].first; i < obj_vertices[k].first + obj_vertices[k].second; ++i)
            if (!model.fixed[static_cast<size_t>(i)]) v.row(i) = scene.objects[k].velocity.transpose();

    // Masses of free vertices; stiffest spring of each object (for the automatic contact stiffness).
    std::int64_t nfree = 0;
    min_free_mass = std::numeric_limits<double>::infinity();
    object_k.assign(scene.objects.size(), 0.0);
    for (Index e = 0; e < model.springs.edges.rows(); ++e) {
        double& ko = object_k[static_cast<size_t>(mesh.vertex_object[static_cast<size_t>(model.springs.edges(e, 0))])];
        ko = std::max(ko, model.springs.k[static_cast<size_t>(e)]);
    }
    for (Index i = 0; i < n; ++i)
        if (!model.fixed[static_cast<size_t>(i)]) {
            msum += model.mass[static_cast<size_t>(i)];
            min_free_mass = std::min(min_free_mass, model.mass[static_cast<size_t>(i)]);
            ++nfree;
        }
    mean_free_mass = nfree ? msum / static_cast<double>(nfree) : 1.0;
    if (!nfree) min_free_mass = 1.0;
    mu = scene.contact.friction;
    // Ground: automatic stiffness per vertex = the contact stiffness of its object against a partner as stiff
    // as itself (10 × its stiffest spring), automatic damping per vertex sqrt(k m) (half critical).
    model.ground = scene.ground;
    if (model.ground.enabled && (!(model.ground.stiffness > 0) || !(model.ground.damping > 0))) {
        model.ground_k.assign(static_cast<size_t>(n), model.ground.stiffness);
        model.ground_c.assign(static_cast<size_t>(n), model.ground.damping);
        for (Index i = 0; i < n; ++i) {
            const size_t o = static_cast<size_t>(mesh.vertex_object[static_cast<size_t>(i)]);
            double& k = model.ground_k[static_cast<size_t>(i)];
            if (!(k > 0))
                k = scene.contact.stiffness > 0 ? scene.contact.stiffness
                                                : pair_stiffness(static_cast<Index>(o), static_cast<Index>(o));
            double& c = model.ground_c[static_cast<size_t>(i)];
            if (!(c > 0)) c = std::sqrt(k * model.mass[static_cast<size_t>(i)]);
        }
        if (model.ground.stiffness > 0) model.ground_k.clear();
        if (model.ground.damping > 0) model.ground_c.clear();
    }

    // Detection only when some pair can collide.
    int dynamic_objects = 0, objects = static_cast<int>(scene.objects.size());
    bool self = false;
    for (const ObjectSpec& o : scene.objects) {
        dynamic_objects += o.is_static ? 0 : 1;
        self = self || (!o.is_static && o.self_collision);
    }
    detect_enabled = dynamic_objects > 0 && (self || objects >= 2);
    if (detect_enabled) {
        detector.set_params(scene.detect);
        detector.set_topology(mesh, options);
        penetration.set_topology(mesh);
    }

    // Stability limit of the explicit integrator (springs, volumes, damping, and per vertex the stiffer of its
    // stiffest possible contact and the ground, with their damping).
    const double h = scene.dt / scene.substeps;
    {
        std::vector<double> extra_k(static_cast<size_t>(n), 0.0), extra_c(static_cast<size_t>(n), 0.0);
        const Index nobj = static_cast<Index>(scene.objects.size());
        std::vector<double> obj_contact_k(static_cast<size_t>(nobj), 0.0);
        if (detect_enabled)
            for (Index a = 0; a < nobj; ++a)
                for (Index b = 0; b < nobj; ++b)
                    if ((a != b || scene.objects[static_cast<size_t>(a)].self_collision) &&
                        !(scene.objects[static_cast<size_t>(a)].is_static &&
                          scene.objects[static_cast<size_t>(b)].is_static))
                        obj_contact_k[static_cast<size_t>(a)] =
                            std::max(obj_contact_k[static_cast<size_t>(a)], pair_stiffness(a, b));
        for (Index i = 0; i < n; ++i) {
            const size_t u = static_cast<size_t>(i);
            double k = obj_contact_k[static_cast<size_t>(mesh.vertex_object[u])];
            if (model.ground.enabled) k = std::max(k, model.ground_k_at(i));
            extra_k[u] = k;
            extra_c[u] = scene.contact.damping > 0 && !model.ground.enabled ? scene.contact.damping
                                                                            : std::sqrt(k * model.mass[u]);
        }
        dt_limit = model.explicit_dt_limit(mesh.positions, extra_k, extra_c);
    }
    if (scene.integrator == Integrator::symplectic_euler && h > dt_limit)
        warnings.push_back("time step " + num(h) + " s (dt/substeps) exceeds the explicit stability limit ≈ " +
                           num(dt_limit) +
                           " s estimated from the largest stiffness/mass ratio; symplectic_euler "
                           "will likely blow up: use more substeps, a smaller dt, or implicit_euler");

    // Reference energy for blow-up detection: all the energy the scene can draw on at start.
    const Energy e0 = model.energy(mesh.positions, v);
    const auto [lo, hi] = bounding_box(mesh.positions);
    double extent = (hi - lo).norm();
    centre0 = 0.5 * (lo + hi);
    radius0 = 0.5 * extent;
    if (model.ground.enabled) extent += std::abs(model.ground.normal.dot(lo) - model.ground.height);
    energy_ref = e0.internal() + msum * model.gravity.norm() * extent;
    if (detect_enabled) {
        double a = 0, b = 0;
        detect_and_respond(a, b);
    }
    energy_ref += contact_energy();
    energy_ref = std::max(energy_ref, 1e-12 * std::max(1.0, msum));
    // Fastest any vertex can move if all the energy the blow-up test allows went into it.
    speed_bound = std::sqrt(2 * 1e3 * energy_ref / min_free_mass);
}

double SimulationImpl::pair_stiffness(Index a, Index b) const
{
    // 10 × the harmonic mean of the stiffest springs of the two objects: dominated by the softer one, so a
    // very stiff object pressing on a soft one gets a contact about as stiff as the soft one can bear. A static
    // object (no springs) counts as stiff as its partner.
    if (scene.contact.stiffness > 0) return scene.contact.stiffness;
    double ka = object_k[static_cast<size_t>(a)], kb = object_k[static_cast<size_t>(b)];
    if (!(ka > 0)) ka = kb;
    if (!(kb > 0)) kb = ka;
    if (!(ka > 0)) return 1e4; // two objects without springs (cannot happen for a contact the detector reports)
    return 10 * 2 * ka * kb / (ka + kb);
}

void SimulationImpl::contact_coefficients()
{
    const size_t nc = contacts.size();
    contact_k.resize(nc);
    contact_c.resize(nc);
    contact_mred.resize(nc);
    for (size_t q = 0; q < nc; ++q) {
        const Contact& c = contacts[q];
        contact_k[q] = pair_stiffness(mesh.vertex_object[static_cast<size_t>(c.vertex)], c.tet_object);
        // Reduced mass of the vertex and the penetrated tet's point (fixed vertices have infinite mass).
        double inv_v =
            model.fixed[static_cast<size_t>(c.vertex)] ? 0.0 : 1.0 / model.mass[static_cast<size_t>(c.vertex)];
        double mt = 0;
        bool tet_fixed = false;
        for (int k = 0; k < 4; ++k) {
            const size_t j = static_cast<size_t>(mesh.tets(c.tet, k));
            if (model.fixed[j] && c.bary[k] > 0.25) tet_fixed = true;
            mt += c.bary[k] * model.mass[j];
        }
        const double inv_t = tet_fixed || !(mt > 0) ? 0.0 : 1.0 / mt;
        const double inv = inv_v + inv_t;
        contact_mred[q] = inv > 0 ? 1.0 / inv : 0.0;
        contact_c[q] = scene.contact.damping > 0 ? scene.contact.damping : std::sqrt(contact_k[q] * contact_mred[q]);
    }
}

void SimulationImpl::detect_and_respond(double& ms_detect, double& ms_response)
{
    if (!detect_enabled) {
        contacts.clear();
        contact_weight.clear();
        contact_coefficients();
        return;
    }
    auto t0 = Clock::now();
    const std::vector<Contact>& found = detector.detect(mesh.positions);
    ms_detect += ms_since(t0);
    t0 = Clock::now();
    contacts.assign(found.begin(), found.end());
    penetration.compute(mesh.positions, contacts);
    contact_coefficients();
    // Weight: a vertex inside k tets of one object (on shared faces) gets 1/k of the response from each.
    contact_weight.assign(contacts.size(), 1.0);
    for (size_t a = 0; a < contacts.size();) {
        size_t b = a;
        while (b < contacts.size() && contacts[b].vertex == contacts[a].vertex)
            ++b;
        for (size_t i = a; i < b; ++i) {
            int same = 0;
            for (size_t j = a; j < b; ++j)
                same += contacts[j].tet_object == contacts[i].tet_object ? 1 : 0;
            contact_weight[i] = 1.0 / same;
        }
        a = b;
    }
    ms_response += ms_since(t0);
}

void SimulationImpl::add_contact_forces(const Positions& vel, Positions& f, double h, bool cap) const
{
    for (size_t q = 0; q < contacts.size(); ++q) {
        const Contact& c = contacts[q];
        if (!(c.depth > 0)) continue;
        const Vec3 nrm(c.direction[0], c.direction[1], c.direction[2]);
        Vec3 vrel = vel.row(c.vertex).transpose();
        for (int k = 0; k < 4; ++k)
            vrel -= c.bary[k] * vel.row(mesh.tets(c.tet, k)).transpose();
        const double vn = vrel.dot(nrm);
        const double w = contact_weight[q];
        double scale = 1.0;
        if (cap && contact_k[q] > 0) scale = std::min(1.0, 0.5 * contact_mred[q] / (h * h * contact_k[q]));
        const double fn = w * std::max(0.0, scale * (contact_k[q] * c.depth - contact_c[q] * vn));
        Vec3 force = fn * nrm;
        if (mu > 0 && fn > 0) {
            // Coulomb friction along the relative tangential velocity, smoothed below 1 mm/s and capped so
            // that it cannot reverse the relative sliding in one step.
            const Vec3 vt = vrel - vn * nrm;
            const double speed = vt.norm();
            double ft = mu * fn * std::min(1.0, speed / 1e-3);
            if (h > 0 && contact_mred[q] > 0) ft = std::min(ft, w * contact_mred[q] * speed / h);
            if (speed > 0) force -= ft * vt / speed;
        }
        f.row(c.vertex) += force.transpose();
        for (int k = 0; k < 4; ++k)
            f.row(mesh.tets(c.tet, k)) -= c.bary[k] * force.transpose();
    }
}

void SimulationImpl::add_contact_triplets(double scale_k, double scale_c,
                                          std::vector<Eigen::Triplet<double>>& out) const
{
    for (size_t q = 0; q < contacts.size(); ++q) {
        const Contact& c = contacts[q];
        if (!(c.depth > 0)) continue;
        const Vec3 nrm(c.direction[0], c.direction[1], c.direction[2]);
        const Mat3 nn = contact_weight[q] * (scale_k * contact_k[q] + scale_c * contact_c[q]) * nrm * nrm.transpose();
        const Index node[5] = {c.vertex, mesh.tets(c.tet, 0), mesh.tets(c.tet, 1), mesh.tets(c.tet, 2),
                               mesh.tets(c.tet, 3)};
        const double coef[5] = {1.0, -c.bary[0], -c.bary[1], -c.bary[2], -c.bary[3]};
        for (int a = 0; a < 5; ++a) {
            if (model.fixed[static_cast<size_t>(node[a])]) continue;
            for (int b = 0; b < 5; ++b) {
                if (model.fixed[static_cast<size_t>(node[b])]) continue;
                const Mat3 blk = coef[a] * coef[b] * nn;
                for (int r = 0; r < 3; ++r)
                    for (int cc2 = 0; cc2 < 3; ++cc2)
                        if (blk(r, cc2) != 0) out.emplace_back(3 * node[a] + r, 3 * node[b] + cc2, blk(r, cc2));
            }
        }
    }
}

double SimulationImpl::contact_energy() const
{
    double e = 0;
    for (size_t q = 0; q < contacts.size(); ++q)
        if (contacts[q].depth > 0) e += 0.5 * contact_weight[q] * contact_k[q] * contacts[q].depth * contacts[q].depth;
    return e;
}

bool SimulationImpl::state_finite() const
{
    return mesh.positions.allFinite() && v.allFinite();
}

std::string SimulationImpl::check_state(double t_end) const
{
    // Cheap per-substep divergence test (O(n)): finite state, every free vertex within the distance it could
    // have travelled on the energy available at start (with margin), and a kinetic energy below the bound of
    // the per-step energy test. Catches a blow-up before positions become so large that detection fails.
    const Index n = mesh.num_vertices();
    const double g = model.gravity.norm();
    const double reach = 10 * (radius0 + speed_bound * t_end + 0.5 * g * t_end * t_end) + 1.0;
    double kinetic = 0, far = 0;
    Index far_vertex = -1;
    for (Index i = 0; i < n; ++i) {
        if (model.fixed[static_cast<size_t>(i)]) continue;
        const Vec3 xi = mesh.positions.row(i).transpose(), vi = v.row(i).transpose();
        if (!xi.allFinite() || !vi.allFinite())
            return "vertex " + std::to_string(i) + " has a non-finite position or velocity (NaN/Inf)";
        const double d = (xi - centre0).norm();
        if (d > far) {
            far = d;
            far_vertex = i;
        }
        kinetic += 0.5 * model.mass[static_cast<size_t>(i)] * vi.squaredNorm();
    }
    if (far > reach)
        return "vertex " + std::to_string(far_vertex) + " is " + num(far) + " from the scene centre, beyond the " +
               num(reach) + " it could reach on the energy available at start";
    const double kinetic_bound = 1e3 * energy_ref + msum * g * (reach + radius0);
    if (kinetic > kinetic_bound)
        return "the kinetic energy grew to " + num(kinetic) + ", " + num(kinetic / energy_ref) +
               " times all the energy available at start";
    return {};
}

void SimulationImpl::substep_symplectic(double h)
{
    const Index n = mesh.num_vertices();
    Positions f = Positions::Zero(n, 3);
    Model::ForceOptions opt;
    opt.h = h;
    model.add_forces(mesh.positions, v, f, opt);
    add_contact_forces(v, f, h, false);
    for (Index i = 0; i < n; ++i) {
        if (model.fixed[static_cast<size_t>(i)]) continue;
        v.row(i) += h / model.mass[static_cast<size_t>(i)] * f.row(i);
        mesh.positions.row(i) += h * v.row(i);
    }
}

void SimulationImpl::contact_apply(double scale_k, double scale_c, const Eigen::VectorXd& p, Eigen::VectorXd& out) const
{
    auto free = [&](Index i) { return !model.fixed[static_cast<size_t>(i)]; };
    for (size_t q = 0; q < contacts.size(); ++q) {
        const Contact& c = contacts[q];
        if (!(c.depth > 0)) continue;
        const Vec3 nrm(c.direction[0], c.direction[1], c.direction[2]);
        const Index node[5] = {c.vertex, mesh.tets(c.tet, 0), mesh.tets(c.tet, 1), mesh.tets(c.tet, 2),
                               mesh.tets(c.tet, 3)};
        const double coef[5] = {1.0, -c.bary[0], -c.bary[1], -c.bary[2], -c.bary[3]};
        double jp = 0;
        for (int a = 0; a < 5; ++a)
            if (free(node[a])) jp += coef[a] * nrm.dot(p.segment<3>(3 * node[a]));
        const Vec3 y = contact_weight[q] * (scale_k * contact_k[q] + scale_c * contact_c[q]) * jp * nrm;
        for (int a = 0; a < 5; ++a)
            if (free(node[a])) out.segment<3>(3 * node[a]) += coef[a] * y;
    }
}

void SimulationImpl::contact_diagonal(double scale_k, double scale_c, Eigen::VectorXd& diag) const
{
    for (size_t q = 0; q < contacts.size(); ++q) {
        const Contact& c = contacts[q];
        if (!(c.depth > 0)) continue;
        const Vec3 nrm(c.direction[0], c.direction[1], c.direction[2]);
        const Index node[5] = {c.vertex, mesh.tets(c.tet, 0), mesh.tets(c.tet, 1), mesh.tets(c.tet, 2),
                               mesh.tets(c.tet, 3)};
        const double coef[5] = {1.0, -c.bary[0], -c.bary[1], -c.bary[2], -c.bary[3]};
        const double s = contact_weight[q] * (scale_k * contact_k[q] + scale_c * contact_c[q]);
        for (int a = 0; a < 5; ++a)
            if (!model.fixed[static_cast<size_t>(node[a])])
                diag.segment<3>(3 * node[a]) += coef[a] * coef[a] * s * nrm.cwiseProduct(nrm);
    }
}

int SimulationImpl::substep_implicit(double h)
{
    // Backward Euler linearised once (Baraff & Witkin 1998): with K = −∂f/∂x, C = −∂f/∂v at the start of
    // the step, (M + hC + h²K) v⁺ = M v + h f + h C v, then x⁺ = x + h v⁺.
    const Index n = mesh.num_vertices();
    const Index N = 3 * n;
    Positions f = Positions::Zero(n, 3);
    Model::ForceOptions opt;
    opt.h = h;
    model.add_forces(mesh.positions, v, f, opt);
    add_contact_forces(v, f, h, false);
    const bool cin = scene.contact.in_matrix;
    const Eigen::VectorXd vflat = Eigen::Map<const Eigen::VectorXd>(v.data(), N);
    Eigen::VectorXd cv = Eigen::VectorXd::Zero(N);
    model.apply_matrix(mesh.positions, 0.0, 1.0, vflat, cv);
    if (cin) contact_apply(0.0, 1.0, vflat, cv);
    Eigen::VectorXd rhs(N), mdiag(N);
    for (Index i = 0; i < n; ++i) {
        const bool fx = model.fixed[static_cast<size_t>(i)];
        const double m = model.mass[static_cast<size_t>(i)];
        for (int r = 0; r < 3; ++r) {
            mdiag[3 * i + r] = fx ? 1.0 : m;
            rhs[3 * i + r] = fx ? 0.0 : m * vflat[3 * i + r] + h * f(i, r) + h * cv[3 * i + r];
        }
    }
    Eigen::VectorXd vnew;
    int iterations = 0;
    if (scene.solver == LinearSolver::ldlt) {
        std::vector<Eigen::Triplet<double>> t;
        model.add_matrix_triplets(mesh.positions, h * h, h, t);
        if (cin) add_contact_triplets(h * h, h, t);
        for (Index k = 0; k < N; ++k)
            t.emplace_back(k, k, mdiag[k]);
        SpMat A(N, N);
        A.setFromTriplets(t.begin(), t.end());
        Eigen::SimplicialLDLT<SpMat> solver(A);
        if (solver.info() != Eigen::Success)
            throw RunFailure("the implicit Euler system matrix could not be factorised");
        vnew = solver.solve(rhs);
    } else {
        // Matrix-free preconditioned CG (Jacobi): no assembly, a few sweeps over springs and tets per iteration.
        lin.update(model, mesh.positions, h * h, h);
        auto apply = [&](const Eigen::VectorXd& p, Eigen::VectorXd& out) {
            out = mdiag.cwiseProduct(p);
            lin.apply(p, out);
            if (cin) contact_apply(h * h, h, p, out);
        };
        Eigen::VectorXd diag = mdiag;
        lin.add_diagonal(diag);
        if (cin) contact_diagonal(h * h, h, diag);
        const Eigen::VectorXd inv = diag.cwiseInverse();
        vnew = vflat;
        for (Index i = 0; i < n; ++i)
            if (model.fixed[static_cast<size_t>(i)]) vnew.segment<3>(3 * i).setZero();
        Eigen::VectorXd r(N), z(N), p(N), ap(N);
        apply(vnew, ap);
        r = rhs - ap;
        const double bnorm = std::max(rhs.norm(), 1e-300);
        z = inv.cwiseProduct(r);
        p = z;
        double rz = r.dot(z);
        const int max_it = std::max<int>(200, static_cast<int>(N));
        while (iterations < max_it && r.norm() > scene.tolerance * bnorm) {
            apply(p, ap);
            const double pap = p.dot(ap);
            if (!(pap > 0)) break;
            const double alpha = rz / pap;
            vnew += alpha * p;
            r -= alpha * ap;
            z = inv.cwiseProduct(r);
            const double rz_new = r.dot(z);
            p = z + (rz_new / rz) * p;
            rz = rz_new;
            ++iterations;
        }
    }
    for (Index i = 0; i < n; ++i) {
        if (model.fixed[static_cast<size_t>(i)]) continue;
        v.row(i) = vnew.segment<3>(3 * i).transpose();
        mesh.positions.row(i) += h * v.row(i);
    }
    return iterations;
}

void SimulationImpl::setup_local_global(double h)
{
    const Index n = mesh.num_vertices();
    lg_free.assign(static_cast<size_t>(n), -1);
    Index nf = 0;
    for (Index i = 0; i < n; ++i)
        if (!model.fixed[static_cast<size_t>(i)]) lg_free[static_cast<size_t>(i)] = nf++;
    std::vector<Eigen::Triplet<double>> t;
    for (Index i = 0; i < n; ++i)
        if (lg_free[static_cast<size_t>(i)] >= 0)
            t.emplace_back(lg_free[static_cast<size_t>(i)], lg_free[static_cast<size_t>(i)],
                           model.mass[static_cast<size_t>(i)]);
    for (Index e = 0; e < model.springs.edges.rows(); ++e) {
        const Index fi = lg_free[static_cast<size_t>(model.springs.edges(e, 0))];
        const Index fj = lg_free[static_cast<size_t>(model.springs.edges(e, 1))];
        const double w = h * h * model.springs.k[static_cast<size_t>(e)] + h * model.springs.c[static_cast<size_t>(e)];
        if (fi >= 0) t.emplace_back(fi, fi, w);
        if (fj >= 0) t.emplace_back(fj, fj, w);
        if (fi >= 0 && fj >= 0) {
            t.emplace_back(fi, fj, -w);
            t.emplace_back(fj, fi, -w);
        }
    }
    lg_matrix.resize(nf, nf);
    lg_matrix.setFromTriplets(t.begin(), t.end());
    lg_solver.compute(lg_matrix);
    if (lg_solver.info() != Eigen::Success) throw RunFailure("local/global: the global matrix could not be factorised");
    // The volume term stays explicit in this integrator: scale it down to its own stability limit at h.
    Model vol_only = model;
    vol_only.springs = Springs{};
    for (double& c : vol_only.springs.c)
        c = 0;
    const double w2 = vol_only.omega_max_sq(mesh.rest());
    lg_vol_scale = (w2 * h * h > 1.0) ? 1.0 / (w2 * h * h) : 1.0;
    lg_h = h;
}

void SimulationImpl::substep_local_global(double h)
{
    if (h != lg_h) setup_local_global(h);
    const Index n = mesh.num_vertices();
    const Index nf = static_cast<Index>(lg_matrix.rows());
    // Explicit part: gravity, volume, ground, contacts (stiffness capped at the explicit limit of a vertex).
    Positions f = Positions::Zero(n, 3);
    Model::ForceOptions opt;
    opt.parts = Model::ForceOptions::volume | Model::ForceOptions::gravity | Model::ForceOptions::ground;
    opt.h = h;
    opt.volume_scale = lg_vol_scale;
    if (model.ground.enabled) {
        double ratio = 0; // largest ground stiffness / mass
        for (Index i = 0; i < n; ++i)
            if (!model.fixed[static_cast<size_t>(i)])
                ratio = std::max(ratio, model.ground_k_at(i) / model.mass[static_cast<size_t>(i)]);
        if (ratio > 0) opt.ground_scale = std::min(1.0, 0.5 / (h * h * ratio));
    }
    model.add_forces(mesh.positions, v, f, opt);
    add_contact_forces(v, f, h, true);
    const Positions xn = mesh.positions;
    Positions y = xn;
    for (Index i = 0; i < n; ++i)
        if (!model.fixed[static_cast<size_t>(i)])
            y.row(i) += h * v.row(i) + h * h / model.mass[static_cast<size_t>(i)] * f.row(i);
    Positions x = y;
    Eigen::MatrixXd base(nf, 3), rhs(nf, 3);
    for (Index i = 0; i < n; ++i)
        if (lg_free[static_cast<size_t>(i)] >= 0)
            base.row(lg_free[static_cast<size_t>(i)]) = model.mass[static_cast<size_t>(i)] * y.row(i);
    for (int it = 0; it < scene.iterations; ++it) {
        rhs = base;
        for (Index e = 0; e < model.springs.edges.rows(); ++e) {
            const Index i = model.springs.edges(e, 0), j = model.springs.edges(e, 1);
            const Index fi = lg_free[static_cast<size_t>(i)], fj = lg_free[static_cast<size_t>(j)];
            const Eigen::RowVector3d dx = x.row(i) - x.row(j);
            const double len = dx.norm();
            const double kh2 = h * h * model.springs.k[static_cast<size_t>(e)];
            const double ch = h * model.springs.c[static_cast<size_t>(e)];
            const Eigen::RowVector3d d = len > 0
                                             ? Eigen::RowVector3d(model.springs.rest[static_cast<size_t>(e)] / len * dx)
                                             : Eigen::RowVector3d::Zero();
            const Eigen::RowVector3d term = kh2 * d + ch * (xn.row(i) - xn.row(j));
            if (fi >= 0)
                rhs.row(fi) += term + (fj < 0 ? Eigen::RowVector3d((kh2 + ch) * x.row(j)) : Eigen::RowVector3d::Zero());
            if (fj >= 0)
                rhs.row(fj) -= term - (fi < 0 ? Eigen::RowVector3d((kh2 + ch) * x.row(i)) : Eigen::RowVector3d::Zero());
        }
        const Eigen::MatrixXd sol = lg_solver.solve(rhs);
        for (Index i = 0; i < n; ++i)
            if (lg_free[static_cast<size_t>(i)] >= 0) x.row(i) = sol.row(lg_free[static_cast<size_t>(i)]);
    }
    for (Index i = 0; i < n; ++i) {
        if (model.fixed[static_cast<size_t>(i)]) continue;
        v.row(i) = (x.row(i) - xn.row(i)) / h;
    }
    mesh.positions = x;
}

std::string SimulationImpl::likely_cause(double h) const
{
    if (scene.integrator == Integrator::symplectic_euler && h > dt_limit)
        return "the time step " + num(h) + " s exceeds the explicit stability limit ≈ " + num(dt_limit) +
               " s (stiffness/mass too high for symplectic_euler): use substeps, a smaller dt or implicit_euler";
    double depth = 0, kmax = 0;
    for (size_t q = 0; q < contacts.size(); ++q)
        if (contacts[q].depth > depth) {
            depth = contacts[q].depth;
            kmax = std::max(kmax, contact_k[q]);
        }
    if (depth > 0)
        return "contact response (max penetration " + num(depth) + ", contact stiffness up to " + num(kmax) +
               "): lower contact.stiffness or dt, or raise substeps";
    return "stiffness too high for the time step " + num(h) + " s (explicit limit ≈ " + num(dt_limit) +
           " s): lower dt, raise substeps or use implicit_euler";
}

// ---- Simulation ----------------------------------------------------------------------------------

Simulation::Simulation(const Scene& scene) : m_impl(std::make_unique<SimulationImpl>(scene)) {}
Simulation::~Simulation() = default;
Simulation::Simulation(Simulation&&) noexcept = default;
Simulation& Simulation::operator=(Simulation&&) noexcept = default;

void Simulation::step()
{
    SimulationImpl& s = *m_impl;
    const Positions x_save = s.mesh.positions, v_save = s.v;
    const double h = s.scene.dt / s.scene.substeps;
    StepStats st;
    const std::int64_t step_no = s.steps_done + 1;
    int sub = 0;
    auto fail = [&](const std::string& what) {
        s.mesh.positions = x_save;
        s.v = v_save;
        const std::string where = s.scene.substeps > 1 && sub < s.scene.substeps
                                      ? ", substep " + std::to_string(sub + 1) + "/" + std::to_string(s.scene.substeps)
                                      : std::string();
        throw RunFailure("simulation blew up at step " + std::to_string(step_no) + where +
                         " (t = " + num(s.t + (sub < s.scene.substeps ? sub + 1 : s.scene.substeps) * h) +
                         " s): " + what + "; likely cause: " + s.likely_cause(h));
    };
    for (; sub < s.scene.substeps; ++sub) {
        try {
            s.detect_and_respond(st.ms_detect, st.ms_response);
        } catch (const Error& e) {
            // The input was checked at construction: a detector error now comes from the state (a vertex
            // flung far away, a tet stretched over millions of cells), i.e. from a diverging run.
            fail(std::string("collision detection failed (") + e.what() + ")");
        }
        const auto t0 = Clock::now();
        switch (s.scene.integrator) {
        case Integrator::symplectic_euler:
            s.substep_symplectic(h);
            break;
        case Integrator::vbd:
        case Integrator::implicit_euler:
            st.solver_iterations += s.substep_implicit(h);
            break;
        case Integrator::local_global:
            s.substep_local_global(h);
            break;
        }
        st.ms_integrate += ms_since(t0);
        const std::string bad = s.check_state(s.t + (sub + 1) * h);
        if (!bad.empty()) fail(bad);
    }
    const Energy e = s.model.energy(s.mesh.positions, s.v);
    const double internal = e.internal() + s.contact_energy();
    if (!std::isfinite(internal)) fail("the energy became NaN/Inf");
    if (internal > 1e3 * s.energy_ref)
        fail("the energy grew to " + num(internal) + ", " + num(internal / s.energy_ref) +
             " times all the energy available at start");
    st.contacts = static_cast<std::int64_t>(s.contacts.size());
    double sum = 0;
    for (const Contact& c : s.contacts) {
        const double d = c.depth > 0 ? c.depth : 0.0;
        st.max_depth = std::max(st.max_depth, d);
        sum += d;
    }
    st.mean_depth = s.contacts.empty() ? 0.0 : sum / static_cast<double>(s.contacts.size());
    s.stats = st;
    ++s.steps_done;
    s.t += s.scene.dt;
}

const Scene& Simulation::scene() const
{
    return m_impl->scene;
}
std::int64_t Simulation::step_index() const
{
    return m_impl->steps_done;
}
double Simulation::time() const
{
    return m_impl->t;
}
const TetMesh& Simulation::mesh() const
{
    return m_impl->mesh;
}
const Positions& Simulation::positions() const
{
    return m_impl->mesh.positions;
}
const Positions& Simulation::velocities() const
{
    return m_impl->v;
}
const Model& Simulation::model() const
{
    return m_impl->model;
}
std::pair<Index, Index> Simulation::object_vertices(int k) const
{
    return m_impl->obj_vertices.at(static_cast<size_t>(k));
}
std::pair<Index, Index> Simulation::object_tets(int k) const
{
    return m_impl->obj_tets.at(static_cast<size_t>(k));
}

Energy Simulation::energy() const
{
    Energy e = m_impl->model.energy(m_impl->mesh.positions, m_impl->v);
    e.contact = m_impl->contact_energy();
    return e;
}

Eigen::Vector3d Simulation::momentum() const
{
    Vec3 p = Vec3::Zero();
    for (Index i = 0; i < m_impl->mesh.num_vertices(); ++i)
        if (!m_impl->model.fixed[static_cast<size_t>(i)])
            p += m_impl->model.mass[static_cast<size_t>(i)] * m_impl->v.row(i).transpose();
    return p;
}

const std::vector<Contact>& Simulation::contacts() const
{
    return m_impl->contacts;
}

double Simulation::max_penetration() const
{
    double d = 0;
    for (const Contact& c : m_impl->contacts)
        if (c.depth > d) d = c.depth;
    return d;
}

double Simulation::mean_penetration() const
{
    if (m_impl->contacts.empty()) return 0;
    double s = 0;
    for (const Contact& c : m_impl->contacts)
        s += c.depth > 0 ? c.depth : 0.0;
    return s / static_cast<double>(m_impl->contacts.size());
}

std::vector<double> Simulation::exact_depths() const
{
    if (!m_impl->detect_enabled) return {};
    return m_impl->penetration.exact_depths(m_impl->mesh.positions, m_impl->contacts);
}

void Simulation::refresh_contacts()
{
    double a = 0, b = 0;
    m_impl->detect_and_respond(a, b);
}

double Simulation::contact_stiffness(int a, int b) const
{
    const int n = static_cast<int>(m_impl->scene.objects.size());
    if (a < 0 || a >= n || b < 0 || b >= n)
        throw Error("contact_stiffness: object index out of range (" + std::to_string(a) + ", " + std::to_string(b) +
                    "; " + std::to_string(n) + " objects)");
    return m_impl->pair_stiffness(a, b);
}

const StepStats& Simulation::last_stats() const
{
    return m_impl->stats;
}
double Simulation::explicit_dt_limit() const
{
    return m_impl->dt_limit;
}
const std::vector<std::string>& Simulation::warnings() const
{
    return m_impl->warnings;
}

io::Fields Simulation::output_fields() const
{
    const SimulationImpl& s = *m_impl;
    const Index n = s.mesh.num_vertices();
    auto wanted = [&](const char* name) {
        return std::find(s.scene.output.fields.begin(), s.scene.output.fields.end(), name) !=
               s.scene.output.fields.end();
    };
    io::Fields f;
    if (wanted("velocity")) {
        io::Field fl{"velocity", 3, {}};
        fl.values.assign(s.v.data(), s.v.data() + 3 * n);
        f.point.push_back(std::move(fl));
    }
    if (wanted("contact") || wanted("depth")) {
        std::vector<double> flag(static_cast<size_t>(n), 0.0), depth(static_cast<size_t>(n), 0.0);
        for (const Contact& c : s.contacts) {
            flag[static_cast<size_t>(c.vertex)] = 1.0;
            if (c.depth > depth[static_cast<size_t>(c.vertex)]) depth[static_cast<size_t>(c.vertex)] = c.depth;
        }
        if (wanted("contact")) f.point.push_back(io::Field{"contact", 1, std::move(flag)});
        if (wanted("depth")) f.point.push_back(io::Field{"penetration_depth", 1, std::move(depth)});
    }
    if (wanted("object")) {
        io::Field fl{"object", 1, {}};
        for (Index t : s.mesh.tet_object)
            fl.values.push_back(static_cast<double>(t));
        f.cell.push_back(std::move(fl));
    }
    return f;
}

} // namespace tethash::sim
