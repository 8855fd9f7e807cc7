// The compiled half of the Python package `tethash` (python/tethash/__init__.py is the other): the detector on
// numpy arrays, mesh reading and writing, and the simulate/study entry points the command line runs.
//
// Array rules (docs/embedding.md, "Python"): positions are float64 (n, 3) and tets int32 (m, 4). A C-contiguous
// array of that dtype is read where it lies (no copy; Detector.positions_address tells the address the detector
// read); a strided or Fortran-ordered one is copied once into a C-contiguous buffer (Detector.positions_copied).
// Another dtype, dimension or column count is a TypeError/ValueError naming the argument: converting silently
// would hide a copy per call (float32 positions) or a precision loss (int64 ids).
#include "tethash/ccd.hpp"
#include "tethash/continuous.hpp"
#include "tethash/detect.hpp"
#include "tethash/detect_grammar.hpp"
#include "tethash/edge_contacts.hpp"
#include "tethash/error.hpp"
#include "tethash/io/mesh_io.hpp"
#include "tethash/oracle.hpp"
#include "tethash/penetration.hpp"
#include "tethash/sim/scene.hpp"
#include "tethash/sim/simulation.hpp"
#include "tethash/study/study.hpp"

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <iterator>
#include <limits>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace py = pybind11;

namespace {

using tethash::Index;

/// A numpy array as an Eigen map of `Cols` columns, checked; `keep` owns the copy when one was made.
template <typename Scalar, int Cols> struct ArrayView {
    using Matrix = Eigen::Matrix<Scalar, Eigen::Dynamic, Cols, Eigen::RowMajor>;
    py::array keep;
    const Scalar* data = nullptr;
    Eigen::Index rows = 0;
    bool copied = false;
    Eigen::Map<const Matrix> map() const { return Eigen::Map<const Matrix>(data, rows, Cols); }
};

std::string dtype_name(const py::array& a)
{
    return py::str(a.dtype()).cast<std::string>();
}

/// Checks `obj` is a numpy array of Scalar with shape (rows, Cols); copies it once if it is not C-contiguous.
template <typename Scalar, int Cols>
ArrayView<Scalar, Cols> view_of(const py::handle& obj, const char* name, const char* dtype_text)
{
    if (!py::isinstance<py::array>(obj))
        throw py::type_error(std::string(name) + ": expected a numpy array of " + dtype_text + " with shape (n, " +
                             std::to_string(Cols) + "), found " + py::str(py::type::of(obj)).cast<std::string>());
    py::array a = py::reinterpret_borrow<py::array>(obj);
    const py::dtype want = py::dtype::of<Scalar>();
    if (!want.attr("__eq__")(a.dtype()).template cast<bool>())
        throw py::type_error(std::string(name) + ": expected dtype " + dtype_text + ", found " + dtype_name(a) +
                             " (convert once with .astype(numpy." + dtype_text + "))");
    if (a.ndim() != 2 || a.shape(1) != Cols) {
        std::string shape = "(";
        for (py::ssize_t d = 0; d < a.ndim(); ++d)
            shape += (d ? ", " : "") + std::to_string(a.shape(d));
        shape += a.ndim() == 1 ? ",)" : ")";
        throw py::value_error(std::string(name) + ": expected shape (n, " + std::to_string(Cols) + "), found " + shape);
    }
    ArrayView<Scalar, Cols> v;
    if (!(a.flags() & py::array::c_style)) {
        v.keep = py::array_t<Scalar, py::array::c_style>::ensure(a); // the one documented copy
        if (!v.keep) throw py::error_already_set();
        v.copied = true;
    } else {
        v.keep = a;
    }
    v.data = static_cast<const Scalar*>(v.keep.data());
    v.rows = static_cast<Eigen::Index>(a.shape(0));
    return v;
}

ArrayView<double, 3> positions_of(const py::handle& obj, const char* name = "positions")
{
    return view_of<double, 3>(obj, name, "float64");
}
ArrayView<Index, 4> tets_of(const py::handle& obj, const char* name = "tets")
{
    return view_of<Index, 4>(obj, name, "int32");
}

/// An optional 1-D int32 array of `count` ids (None: empty).
std::vector<Index> ids_of(const py::handle& obj, const char* name, std::int64_t count)
{
    if (obj.is_none()) return {};
    if (!py::isinstance<py::array>(obj))
        throw py::type_error(std::string(name) + ": expected a numpy array of int32 or None");
    py::array a = py::reinterpret_borrow<py::array>(obj);
    if (a.dtype().kind() != 'i' && a.dtype().kind() != 'u')
        throw py::type_error(std::string(name) + ": expected an integer array, found " + dtype_name(a));
    if (a.ndim() != 1 || a.shape(0) != count)
        throw py::value_error(
            std::string(name) + ": expected " + std::to_string(count) + " ids (one per " +
            (std::string(name).find("tet") != std::string::npos ? "tet" : "vertex") + "), found " +
            (a.ndim() == 1 ? std::to_string(a.shape(0)) : "an array of " + std::to_string(a.ndim()) + " dims"));
    auto c = py::array_t<std::int64_t, py::array::c_style | py::array::forcecast>::ensure(a);
    std::vector<Index> out(static_cast<std::size_t>(count));
    for (std::int64_t i = 0; i < count; ++i) {
        const std::int64_t x = c.at(i);
        if (x < 0 || x > std::numeric_limits<Index>::max())
            throw py::value_error(std::string(name) + "[" + std::to_string(i) + "]: expected an id >= 0, found " +
                                  std::to_string(x));
        out[static_cast<std::size_t>(i)] = static_cast<Index>(x);
    }
    return out;
}

/// One contact as numpy sees it (dtype tethash.CONTACT_DTYPE): the C++ Contact, field for field.
struct PyContact {
    std::int32_t vertex, tet, vertex_object, tet_object;
    double bary[4];
    double depth;
    double direction[3];
};
static_assert(sizeof(PyContact) == sizeof(tethash::Contact));

py::array_t<PyContact> contacts_array(const std::vector<tethash::Contact>& contacts)
{
    py::array_t<PyContact> out(static_cast<py::ssize_t>(contacts.size()));
    auto* p = static_cast<PyContact*>(out.mutable_data());
    for (std::size_t i = 0; i < contacts.size(); ++i) {
        const tethash::Contact& c = contacts[i];
        PyContact& r = p[i];
        r.vertex = c.vertex;
        r.tet = c.tet;
        r.vertex_object = c.vertex_object;
        r.tet_object = c.tet_object;
        std::memcpy(r.bary, c.bary, sizeof r.bary);
        r.depth = c.depth;
        std::memcpy(r.direction, c.direction, sizeof r.direction);
    }
    return out;
}

/// Detector parameters from keyword arguments (numbers or the text grammar of the command line).
tethash::DetectParams params_of(const py::kwargs& kw, bool& penetration)
{
    tethash::DetectParams p;
    penetration = false;
    const auto text = [](const py::handle& v) { return py::str(v).cast<std::string>(); };
    for (const auto& item : kw) {
        const std::string key = py::str(item.first).cast<std::string>();
        const py::handle v = item.second;
        if (key == "cell_size") {
            if (py::isinstance<py::str>(v))
                tethash::parse_cell_size(text(v), p, "cell_size");
            else {
                p.cell_size_mode = tethash::DetectParams::CellSizeMode::absolute; // a length; checked by set_params
                p.cell_size = v.cast<double>();
            }
        } else if (key == "table_size") {
            p.table_size = tethash::parse_table_size(text(v), 0, "table_size");
        } else if (key == "hash") {
            p.hash = tethash::parse_hash_function(text(v));
        } else if (key == "threads") {
            if (py::isinstance<py::str>(v)) {
                p.threads = tethash::parse_threads(text(v), "threads");
            } else {
                p.threads = tethash::check_threads(v.cast<long long>(), "threads");
            }
        } else if (key == "skin") {
            if (py::isinstance<py::str>(v))
                tethash::parse_skin(text(v), p, "skin");
            else {
                p.skin_mode = tethash::DetectParams::SkinMode::absolute;
                p.skin = v.cast<double>();
            }
        } else if (key == "penetration") {
            penetration = v.cast<bool>();
        } else {
            throw py::type_error("unknown detector parameter '" + key +
                                 "' (cell_size, table_size, hash, threads, skin, penetration)");
        }
    }
    return p;
}

std::vector<tethash::ObjectOptions> objects_of(const py::handle& obj)
{
    std::vector<tethash::ObjectOptions> out;
    if (obj.is_none()) return out;
    std::size_t k = 0;
    for (const py::handle item : obj) {
        tethash::ObjectOptions o;
        const auto d = py::reinterpret_borrow<py::dict>(item);
        for (const auto& kv : d) {
            const std::string key = py::str(kv.first).cast<std::string>();
            if (key == "self_collision")
                o.self_collision = kv.second.cast<bool>();
            else if (key == "static")
                o.is_static = kv.second.cast<bool>();
            else
                throw py::value_error("objects[" + std::to_string(k) + "]: unknown key '" + key +
                                      "' (self_collision, static)");
        }
        out.push_back(o);
        ++k;
    }
    return out;
}

/// tethash.Detector: the C++ Detector plus, on request, penetration depth and direction.
class PyDetector {
  public:
    explicit PyDetector(const py::kwargs& kw) { m_detector.set_params(params_of(kw, m_penetration)); }

    void set_topology(const py::object& tets, Index num_vertices, const py::object& vertex_object,
                      const py::object& tet_object, const py::object& objects)
    {
        const auto t = tets_of(tets);
        const auto vo = ids_of(vertex_object, "vertex_object", num_vertices);
        const auto to = ids_of(tet_object, "tet_object", t.rows);
        const auto opts = objects_of(objects);
        m_detector.set_topology(t.map(), num_vertices, vo, to, opts);
        if (m_penetration) m_depth.set_topology(t.map(), num_vertices, vo, to);
        m_num_vertices = num_vertices;
        m_has_topology = true;
    }

    py::array_t<PyContact> detect(const py::object& positions)
    {
        if (!m_has_topology) throw py::value_error("Detector.detect: call set_topology(tets, num_vertices) first");
        const auto p = positions_of(positions);
        if (p.rows != m_num_vertices)
            throw py::value_error("positions: expected " + std::to_string(m_num_vertices) +
                                  " rows (the vertex count given to set_topology), found " + std::to_string(p.rows));
        m_address = reinterpret_cast<std::uintptr_t>(p.data);
        m_copied = p.copied;
        {
            py::gil_scoped_release release;
            const tethash::PositionsRef ref(p.map());
            // What the detector reads: the caller's buffer itself unless a copy was announced.
            m_address = reinterpret_cast<std::uintptr_t>(ref.data());
            m_detector.detect(ref, &m_stats);
            if (m_penetration) m_depth.compute(ref, m_detector.contacts());
        }
        return contacts_array(m_detector.contacts());
    }

    py::dict stats() const
    {
        py::dict d;
        const tethash::DetectStats& s = m_stats;
        d["ms_total"] = s.ms_total;
        d["ms_setup"] = s.ms_setup;
        d["ms_vertices"] = s.ms_vertices;
        d["ms_tets"] = s.ms_tets;
        d["ms_inside"] = s.ms_inside;
        d["ms_sort"] = s.ms_sort;
        d["cell_size"] = s.cell_size;
        d["table_size"] = s.table_size;
        d["threads"] = s.threads;
        d["vertices"] = s.vertices;
        d["tets"] = s.tets;
        d["cells_visited"] = s.cells_visited;
        d["entries_scanned"] = s.entries_scanned;
        d["inside_tests"] = s.inside_tests;
        d["contacts"] = s.contacts;
        d["skin"] = s.skin;
        d["reused"] = s.reused;
        d["memory_bytes"] = s.memory_bytes;
        return d;
    }

    std::uintptr_t address() const { return m_address; }
    bool copied() const { return m_copied; }

  private:
    tethash::Detector m_detector;
    tethash::Penetration m_depth;
    tethash::DetectStats m_stats;
    bool m_penetration = false, m_has_topology = false, m_copied = false;
    Index m_num_vertices = 0;
    std::uintptr_t m_address = 0;
};

template <typename T> py::array_t<T> vector_array(const std::vector<T>& v)
{
    py::array_t<T> out(static_cast<py::ssize_t>(v.size()));
    if (!v.empty()) std::memcpy(out.mutable_data(), v.data(), v.size() * sizeof(T));
    return out;
}

template <typename Matrix> py::array_t<typename Matrix::Scalar> matrix_array(const Matrix& m)
{
    using S = typename Matrix::Scalar;
    py::array_t<S> out({static_cast<py::ssize_t>(m.rows()), static_cast<py::ssize_t>(Matrix::ColsAtCompileTime)});
    if (m.size()) std::memcpy(out.mutable_data(), m.data(), static_cast<std::size_t>(m.size()) * sizeof(S));
    return out;
}

py::dict mesh_dict(const tethash::TetMesh& mesh)
{
    tethash::TetMesh m = mesh;
    m.ensure_object_ids();
    py::dict d;
    d["positions"] = matrix_array(m.positions);
    d["tets"] = matrix_array(m.tets);
    d["vertex_object"] = vector_array(m.vertex_object);
    d["tet_object"] = vector_array(m.tet_object);
    d["vertex_label"] = vector_array(mesh.vertex_label);
    d["tet_label"] = vector_array(mesh.tet_label);
    return d;
}

py::dict read_mesh(const std::string& path, bool linearize)
{
    tethash::io::ReadOptions o;
    o.linearize = linearize;
    tethash::TetMesh mesh;
    {
        py::gil_scoped_release release;
        mesh = tethash::io::read_tet_mesh(path, nullptr, o);
    }
    return mesh_dict(mesh);
}

void write_mesh(const std::string& path, const py::object& positions, const py::object& tets,
                const py::object& vertex_object, const py::object& tet_object)
{
    const auto p = positions_of(positions);
    const auto t = tets_of(tets);
    tethash::TetMesh mesh;
    mesh.positions = p.map();
    mesh.tets = t.map();
    mesh.vertex_object = ids_of(vertex_object, "vertex_object", p.rows);
    mesh.tet_object = ids_of(tet_object, "tet_object", t.rows);
    mesh.check_consistency("write_mesh");
    tethash::io::check_mesh_output_file(path, "path");
    py::gil_scoped_release release;
    tethash::io::write_mesh(path, mesh);
}

/// Runs a scene for its steps (or `steps`); returns per-step figures and the final state.
py::dict simulate_scene(tethash::sim::Scene scene, std::optional<int> steps, std::optional<double> dt,
                        std::optional<int> substeps, std::optional<std::string> integrator, int record_every)
{
    if (steps) {
        if (*steps < 0) throw py::value_error("steps: must be >= 0, found " + std::to_string(*steps));
        scene.steps = *steps;
    }
    if (dt) {
        if (!(*dt > 0) || !std::isfinite(*dt)) throw py::value_error("dt: must be a positive finite time in s");
        scene.dt = *dt;
    }
    if (substeps) {
        if (*substeps < 1) throw py::value_error("substeps: must be >= 1, found " + std::to_string(*substeps));
        scene.substeps = *substeps;
    }
    if (integrator) scene.integrator = tethash::sim::parse_integrator(*integrator);
    if (record_every < 0) throw py::value_error("record_every: must be >= 0");

    const int n = scene.steps;
    std::vector<double> time(n), energy(n), max_depth(n), ms_detect(n), ms_step(n);
    std::vector<std::int64_t> contacts(n);
    std::vector<tethash::Positions> frames;
    std::vector<double> frame_times;
    std::optional<tethash::sim::Simulation> sim;
    double e0 = 0;
    {
        py::gil_scoped_release release;
        sim.emplace(scene);
        e0 = sim->energy().total();
        if (record_every > 0) {
            frames.push_back(sim->positions());
            frame_times.push_back(0);
        }
    }
    for (int s = 0; s < n; ++s) {
        {
            py::gil_scoped_release release;
            sim->step();
        }
        if (PyErr_CheckSignals() != 0) throw py::error_already_set();
        const tethash::sim::StepStats& st = sim->last_stats();
        time[s] = sim->time();
        energy[s] = sim->energy().total();
        max_depth[s] = st.max_depth;
        contacts[s] = st.contacts;
        ms_detect[s] = st.ms_detect;
        ms_step[s] = st.ms_detect + st.ms_depth + st.ms_response + st.ms_integrate;
        if (record_every > 0 && (s + 1) % record_every == 0) {
            frames.push_back(sim->positions());
            frame_times.push_back(sim->time());
        }
    }
    py::dict d;
    d["steps"] = n;
    d["time"] = vector_array(time);
    d["energy_start"] = e0;
    d["energy"] = vector_array(energy);
    d["contacts"] = vector_array(contacts);
    d["max_depth"] = vector_array(max_depth);
    d["ms_detect"] = vector_array(ms_detect);
    d["ms_step"] = vector_array(ms_step);
    d["mesh"] = mesh_dict(sim->mesh());
    d["velocities"] = matrix_array(sim->velocities());
    py::list f;
    for (const auto& p : frames)
        f.append(matrix_array(p));
    d["frames"] = f;
    d["frame_times"] = vector_array(frame_times);
    d["warnings"] = sim->warnings();
    return d;
}

std::vector<std::string> strings_of(const py::handle& obj, const char* name)
{
    std::vector<std::string> out;
    if (obj.is_none()) return out;
    if (py::isinstance<py::str>(obj) || !py::isinstance<py::iterable>(obj)) {
        out.push_back(py::str(obj).cast<std::string>());
        return out;
    }
    for (const py::handle item : obj)
        out.push_back(py::str(item).cast<std::string>());
    if (out.empty()) throw py::value_error(std::string(name) + ": empty list");
    return out;
}

py::dict run_study(const std::string& sweep, const py::dict& kw)
{
    tethash::study::StudyOptions o;
    o.sweep = tethash::study::parse_sweep(sweep);
    const bool simulates = o.sweep == tethash::study::Sweep::integrator || o.sweep == tethash::study::Sweep::stability;
    o.repeat = simulates ? 1 : 3;
    o.warmup = simulates ? 0 : 1;
    bool quiet = true;
    // The arguments that take a list of strings (or one string), each the option of the same name.
    using Options = tethash::study::StudyOptions;
    using List = std::vector<std::string> Options::*;
    static const std::pair<const char*, List> list_options[] = {
        {"meshes", &Options::meshes},         {"cell_size", &Options::cell_size},
        {"table_size", &Options::table_size}, {"hash", &Options::hash},
        {"threads", &Options::threads},       {"grid", &Options::grid},
        {"integrator", &Options::integrator}, {"dt", &Options::dt},
        {"substeps", &Options::substeps},
    };
    for (const auto& item : kw) {
        const std::string key = py::str(item.first).cast<std::string>();
        const py::handle v = item.second;
        if (v.is_none()) continue;
        if (const auto list = std::find_if(std::begin(list_options), std::end(list_options),
                                           [&](const auto& l) { return key == l.first; });
            list != std::end(list_options))
            o.*(list->second) = strings_of(v, list->first);
        else if (key == "scene")
            o.scene_file = py::str(v).cast<std::string>();
        else if (key == "teschner_scenarios")
            o.teschner = v.cast<bool>();
        else if (key == "scenarios")
            o.scenarios = v.cast<std::vector<int>>();
        else if (key == "duration")
            o.duration = v.cast<double>();
        else if (key == "repeat")
            o.repeat = v.cast<int>();
        else if (key == "warmup")
            o.warmup = v.cast<int>();
        else if (key == "oracle")
            o.oracle = v.cast<bool>();
        else if (key == "penetration")
            o.penetration = v.cast<bool>();
        else if (key == "shard")
            tethash::study::parse_shard(py::str(v).cast<std::string>(), o.shard_index, o.shard_count);
        else if (key == "out")
            o.out_dir = py::str(v).cast<std::string>();
        else if (key == "quiet")
            quiet = v.cast<bool>();
        else
            throw py::type_error("study: unknown argument '" + key + "'");
    }
    if (o.repeat < 1) throw py::value_error("repeat: must be >= 1, found " + std::to_string(o.repeat));
    if (o.warmup < 0) throw py::value_error("warmup: must be >= 0, found " + std::to_string(o.warmup));
    o.command_line = "tethash.study('" + sweep + "', ...) (Python)";
    auto plan = tethash::study::plan_study(o);

    std::atomic<bool> stop{false};
    tethash::study::RunHooks hooks;
    hooks.stop = &stop;
    hooks.on_point = [&stop, quiet](std::int64_t k, std::int64_t of, const tethash::study::PointInfo& p) {
        py::gil_scoped_acquire gil;
        if (PyErr_CheckSignals() != 0) {
            PyErr_Clear();
            stop.store(true);
        }
        if (!quiet) py::print("study: point", k + 1, "/", of, ":", p.label());
    };
    tethash::study::StudyResult res;
    {
        py::gil_scoped_release release;
        res = tethash::study::run_study(*plan, hooks);
    }
    if (res.interrupted || stop.load()) { // Ctrl-C: the rows measured so far stay in the CSV
        PyErr_SetNone(PyExc_KeyboardInterrupt);
        throw py::error_already_set();
    }
    py::dict d;
    d["points_done"] = res.points_done;
    d["points_planned"] = res.points_planned;
    d["points_total"] = tethash::study::points_total(*plan);
    d["rows"] = res.rows;
    d["csv"] = res.csv_path;
    d["json"] = res.json_path;
    d["notes"] = res.notes;
    return d;
}

/// A continuous query on two (4, 3) float64 arrays (ccd.hpp): (hit, toi).
py::tuple ccd_query(bool edge_edge, const py::object& start, const py::object& end, double tolerance,
                    std::int64_t max_iterations)
{
    const auto s = positions_of(start, "start"), e = positions_of(end, "end");
    if (s.rows != 4 || e.rows != 4)
        throw py::value_error("start, end: expected shape (4, 3) each, found " + std::to_string(s.rows) + " and " +
                              std::to_string(e.rows) + " rows");
    const auto a = s.map(), b = e.map();
    const auto row = [](const auto& m, int i) { return Eigen::Vector3d(m(i, 0), m(i, 1), m(i, 2)); };
    tethash::ccd::CcdParams params;
    params.tolerance = tolerance;
    params.max_iterations = max_iterations;
    const tethash::ccd::CcdResult r =
        edge_edge ? tethash::ccd::edge_edge_ccd(row(a, 0), row(a, 1), row(a, 2), row(a, 3), row(b, 0), row(b, 1),
                                                row(b, 2), row(b, 3), params)
                  : tethash::ccd::vertex_face_ccd(row(a, 0), row(a, 1), row(a, 2), row(a, 3), row(b, 0), row(b, 1),
                                                  row(b, 2), row(b, 3), params);
    return py::make_tuple(r.hit, r.toi);
}

/// A continuous detection's result as a dict of arrays: kind, a, b, toi, faces, edges and the broad phase's pairs.
py::dict continuous_dict(const tethash::ccd::ContinuousResult& r)
{
    const auto n = static_cast<py::ssize_t>(r.contacts.size());
    py::array_t<std::int8_t> kind(n);
    py::array_t<Index> a(n), b(n);
    py::array_t<double> toi(n);
    for (py::ssize_t i = 0; i < n; ++i) {
        const auto& c = r.contacts[static_cast<std::size_t>(i)];
        kind.mutable_at(i) = static_cast<std::int8_t>(c.kind);
        a.mutable_at(i) = c.a;
        b.mutable_at(i) = c.b;
        toi.mutable_at(i) = c.toi;
    }
    py::array_t<Index> faces({static_cast<py::ssize_t>(r.faces.rows()), py::ssize_t{3}});
    py::array_t<Index> edges({static_cast<py::ssize_t>(r.edges.rows()), py::ssize_t{2}});
    std::copy(r.faces.data(), r.faces.data() + r.faces.size(), faces.mutable_data());
    std::copy(r.edges.data(), r.edges.data() + r.edges.size(), edges.mutable_data());
    py::dict d;
    d["kind"] = kind;
    d["a"] = a;
    d["b"] = b;
    d["toi"] = toi;
    d["faces"] = faces;
    d["edges"] = edges;
    d["broad_phase_pairs"] = r.broad_phase_pairs;
    return d;
}

tethash::ccd::ContinuousParams continuous_params(int threads, double tolerance, std::int64_t max_iterations)
{
    tethash::ccd::ContinuousParams params;
    params.threads = threads;
    params.query.tolerance = tolerance;
    params.query.max_iterations = max_iterations;
    return params;
}

/// Continuous detection over a step (continuous.hpp) as a dict of arrays.
py::dict detect_continuous(const py::object& tets, const py::object& x0, const py::object& x1, int threads,
                           double tolerance, std::int64_t max_iterations)
{
    const auto t = tets_of(tets);
    const auto p0 = positions_of(x0, "x0"), p1 = positions_of(x1, "x1");
    const tethash::ccd::ContinuousParams params = continuous_params(threads, tolerance, max_iterations);
    tethash::ccd::ContinuousResult r;
    {
        py::gil_scoped_release release;
        r = tethash::ccd::detect_continuous(t.map(), p0.map(), p1.map(), params);
    }
    return continuous_dict(r);
}

/// tethash.ContinuousDetector: continuous detection (continuous.hpp) kept between calls on a fixed topology, with
/// its locality rule.
class PyContinuousDetector {
  public:
    void set_topology(const py::object& tets, Index num_vertices)
    {
        if (num_vertices < 0)
            throw tethash::Error("ContinuousDetector.set_topology: num_vertices must be >= 0, found " +
                                 std::to_string(num_vertices));
        const auto t = tets_of(tets);
        m_has_topology = false;
        m_detector.set_topology(t.map(), num_vertices);
        m_num_vertices = num_vertices;
        m_has_topology = true;
    }

    void set_locality(const py::object& rest, const py::object& vertex_group, const py::object& reach_sq)
    {
        ready("set_locality");
        const auto r = positions_of(rest, "rest");
        if (r.rows != m_num_vertices)
            throw tethash::Error("ContinuousDetector.set_locality: rest has " + std::to_string(r.rows) +
                                 " rows, expected " + std::to_string(m_num_vertices) +
                                 " (the vertex count given to set_topology)");
        if (vertex_group.is_none()) throw py::type_error("vertex_group: expected a numpy array of int32, found None");
        const std::vector<Index> groups = ids_of(vertex_group, "vertex_group", m_num_vertices);
        const auto q = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(reach_sq);
        if (!q || q.ndim() != 1)
            throw py::type_error("reach_sq: expected a one-dimensional array of squared reaches (one per group)");
        const std::vector<double> reaches(q.data(), q.data() + q.shape(0));
        m_detector.set_locality(r.map(), groups, reaches);
    }

    py::dict detect(const py::object& x0, const py::object& x1, int threads, double tolerance,
                    std::int64_t max_iterations)
    {
        ready("detect");
        const auto p0 = positions_of(x0, "x0"), p1 = positions_of(x1, "x1");
        if (p0.rows != m_num_vertices || p1.rows != m_num_vertices)
            throw tethash::Error("ContinuousDetector.detect: x0 and x1 have " + std::to_string(p0.rows) + " and " +
                                 std::to_string(p1.rows) + " rows, expected " + std::to_string(m_num_vertices) +
                                 " (the vertex count given to set_topology)");
        const tethash::ccd::ContinuousParams params = continuous_params(threads, tolerance, max_iterations);
        const tethash::ccd::ContinuousResult* r = nullptr;
        {
            py::gil_scoped_release release;
            r = &m_detector.detect(p0.map(), p1.map(), params);
        }
        return continuous_dict(*r);
    }

  private:
    void ready(const char* what) const
    {
        if (!m_has_topology)
            throw tethash::Error(std::string("ContinuousDetector.") + what +
                                 ": call set_topology(tets, num_vertices) first");
    }
    tethash::ccd::ContinuousDetector m_detector;
    Index m_num_vertices = 0;
    bool m_has_topology = false;
};

/// One edge-face contact as numpy sees it (dtype tethash.EDGE_CONTACT_DTYPE): the C++ EdgeFaceContact, field for
/// field (inner_end as int32).
struct PyEdgeContact {
    std::int32_t edge, face, edge_vertices[2], face_vertices[3], edge_object, face_object;
    double edge_t, face_bary[3];
    std::int32_t inner_end;
    double normal[3];
};

/// An EdgeFaceResult as a dict: faces (F, 3), edges (E, 2), contacts (EDGE_CONTACT_DTYPE), candidates.
py::dict edge_result_dict(const tethash::EdgeFaceResult& r)
{
    py::array_t<PyEdgeContact> contacts(static_cast<py::ssize_t>(r.contacts.size()));
    auto* p = static_cast<PyEdgeContact*>(contacts.mutable_data());
    for (std::size_t i = 0; i < r.contacts.size(); ++i) {
        const tethash::EdgeFaceContact& c = r.contacts[i];
        PyEdgeContact& o = p[i];
        o.edge = c.edge;
        o.face = c.face;
        std::copy(std::begin(c.edge_vertices), std::end(c.edge_vertices), o.edge_vertices);
        std::copy(std::begin(c.face_vertices), std::end(c.face_vertices), o.face_vertices);
        o.edge_object = c.edge_object;
        o.face_object = c.face_object;
        o.edge_t = c.edge_t;
        std::copy(std::begin(c.face_bary), std::end(c.face_bary), o.face_bary);
        o.inner_end = c.inner_end;
        std::copy(std::begin(c.normal), std::end(c.normal), o.normal);
    }
    py::dict d;
    d["faces"] = matrix_array(r.faces);
    d["edges"] = matrix_array(r.edges);
    d["contacts"] = contacts;
    d["candidates"] = r.candidates;
    return d;
}

/// tethash.EdgeFaceDetector: edge-face contacts (edge_contacts.hpp) of a fixed topology at changing positions.
class PyEdgeFaceDetector {
  public:
    void set_topology(const py::object& tets, Index num_vertices, const py::object& vertex_object,
                      const py::object& tet_object, const py::object& objects)
    {
        if (num_vertices < 0)
            throw tethash::Error("EdgeFaceDetector.set_topology: num_vertices must be >= 0, found " +
                                 std::to_string(num_vertices));
        const auto t = tets_of(tets);
        const auto vo = ids_of(vertex_object, "vertex_object", num_vertices);
        const auto to = ids_of(tet_object, "tet_object", t.rows);
        const auto opts = objects_of(objects);
        m_detector.set_topology(t.map(), num_vertices, vo, to, opts);
        m_num_vertices = num_vertices;
        m_has_topology = true;
    }

    py::dict find(const py::object& positions, int threads)
    {
        if (!m_has_topology) throw tethash::Error("EdgeFaceDetector.find: call set_topology(tets, num_vertices) first");
        const auto p = positions_of(positions);
        if (p.rows != m_num_vertices)
            throw tethash::Error("EdgeFaceDetector.find: positions has " + std::to_string(p.rows) + " rows, expected " +
                                 std::to_string(m_num_vertices) + " (the vertex count given to set_topology)");
        const tethash::EdgeFaceResult* r = nullptr;
        {
            py::gil_scoped_release release;
            r = &m_detector.find(p.map(), threads);
        }
        return edge_result_dict(*r);
    }

  private:
    tethash::EdgeFaceDetector m_detector;
    Index m_num_vertices = 0;
    bool m_has_topology = false;
};

/// The oracle's edge-face contacts (brute_force_edge_face_contacts): the tests' reference.
py::dict brute_force_edges(const py::object& positions, const py::object& tets, const py::object& vertex_object,
                           const py::object& tet_object, const py::object& objects)
{
    const auto p = positions_of(positions);
    const auto t = tets_of(tets);
    const auto vo = ids_of(vertex_object, "vertex_object", p.rows);
    const auto to = ids_of(tet_object, "tet_object", t.rows);
    const auto opts = objects_of(objects);
    tethash::EdgeFaceResult r;
    {
        py::gil_scoped_release release;
        r = tethash::brute_force_edge_face_contacts(t.map(), p.map(), vo, to, opts);
    }
    return edge_result_dict(r);
}

} // namespace

PYBIND11_MODULE(_tethash, m)
{
    m.doc() = "tethash: spatial-hash collision detection for deformable tetrahedral meshes";
    PYBIND11_NUMPY_DTYPE(PyContact, vertex, tet, vertex_object, tet_object, bary, depth, direction);
    m.attr("CONTACT_DTYPE") = py::dtype::of<PyContact>();
    PYBIND11_NUMPY_DTYPE(PyEdgeContact, edge, face, edge_vertices, face_vertices, edge_object, face_object, edge_t,
                         face_bary, inner_end, normal);
    m.attr("EDGE_CONTACT_DTYPE") = py::dtype::of<PyEdgeContact>();

    static py::exception<tethash::Error> error(m, "Error", PyExc_ValueError);
    static py::exception<tethash::RunFailure> run_failure(m, "RunFailure", PyExc_RuntimeError);
    py::register_exception_translator(
        [](std::exception_ptr p) { // NOLINT(performance-unnecessary-value-param): the translator type pybind11 takes
            try {
                if (p) std::rethrow_exception(p);
            } catch (const tethash::Error& e) {
                PyErr_SetString(error.ptr(), e.what());
            } catch (const tethash::RunFailure& e) {
                PyErr_SetString(run_failure.ptr(), e.what());
            }
        });

    py::class_<PyDetector>(m, "Detector")
        .def(py::init<const py::kwargs&>())
        .def("set_topology", &PyDetector::set_topology, py::arg("tets"), py::arg("num_vertices"),
             py::arg("vertex_object") = py::none(), py::arg("tet_object") = py::none(), py::arg("objects") = py::none())
        .def("detect", &PyDetector::detect, py::arg("positions"))
        .def_property_readonly("stats", &PyDetector::stats)
        .def_property_readonly("positions_address", &PyDetector::address)
        .def_property_readonly("positions_copied", &PyDetector::copied);

    py::class_<PyEdgeFaceDetector>(m, "EdgeFaceDetector")
        .def(py::init<>())
        .def("set_topology", &PyEdgeFaceDetector::set_topology, py::arg("tets"), py::arg("num_vertices"),
             py::arg("vertex_object") = py::none(), py::arg("tet_object") = py::none(), py::arg("objects") = py::none())
        .def("find", &PyEdgeFaceDetector::find, py::arg("positions"), py::arg("threads") = 1);
    m.def("_brute_force_edges", &brute_force_edges, py::arg("positions"), py::arg("tets"),
          py::arg("vertex_object") = py::none(), py::arg("tet_object") = py::none(), py::arg("objects") = py::none());

    m.def(
        "_check_positions", [](const py::object& p) { return static_cast<Index>(positions_of(p).rows); },
        py::arg("positions"));
    m.def("_read_mesh", &read_mesh, py::arg("path"), py::arg("linearize") = false);
    m.def("_write_mesh", &write_mesh, py::arg("path"), py::arg("positions"), py::arg("tets"),
          py::arg("vertex_object") = py::none(), py::arg("tet_object") = py::none());
    m.def(
        "_simulate_file",
        [](const std::string& path, std::optional<int> steps, std::optional<double> dt, std::optional<int> substeps,
           std::optional<std::string> integrator, int record_every) {
            return simulate_scene(tethash::sim::load_scene(path), steps, dt, substeps, std::move(integrator),
                                  record_every);
        },
        py::arg("path"), py::arg("steps"), py::arg("dt"), py::arg("substeps"), py::arg("integrator"),
        py::arg("record_every"));
    m.def(
        "_simulate_text",
        [](const std::string& text, const std::string& source, const std::string& base_dir, std::optional<int> steps,
           std::optional<double> dt, std::optional<int> substeps, std::optional<std::string> integrator,
           int record_every) {
            return simulate_scene(tethash::sim::parse_scene(text, source, base_dir), steps, dt, substeps,
                                  std::move(integrator), record_every);
        },
        py::arg("text"), py::arg("source"), py::arg("base_dir"), py::arg("steps"), py::arg("dt"), py::arg("substeps"),
        py::arg("integrator"), py::arg("record_every"));
    m.def("_default_scene_text", [] { return tethash::sim::default_scene_text(); });
    m.def("_study", &run_study, py::arg("sweep"), py::arg("options"));
    m.def(
        "ccd_vertex_face",
        [](const py::object& start, const py::object& end, double tolerance, std::int64_t max_iterations) {
            return ccd_query(false, start, end, tolerance, max_iterations);
        },
        py::arg("start"), py::arg("end"), py::arg("tolerance") = 1e-6, py::arg("max_iterations") = 1000000);
    m.def(
        "ccd_edge_edge",
        [](const py::object& start, const py::object& end, double tolerance, std::int64_t max_iterations) {
            return ccd_query(true, start, end, tolerance, max_iterations);
        },
        py::arg("start"), py::arg("end"), py::arg("tolerance") = 1e-6, py::arg("max_iterations") = 1000000);
    py::class_<PyContinuousDetector>(m, "ContinuousDetector")
        .def(py::init<>())
        .def("set_topology", &PyContinuousDetector::set_topology, py::arg("tets"), py::arg("num_vertices"))
        .def("set_locality", &PyContinuousDetector::set_locality, py::arg("rest"), py::arg("vertex_group"),
             py::arg("reach_sq"))
        .def("detect", &PyContinuousDetector::detect, py::arg("x0"), py::arg("x1"), py::arg("threads") = 1,
             py::arg("tolerance") = 1e-6, py::arg("max_iterations") = 1000000);
    m.def("detect_continuous", &detect_continuous, py::arg("tets"), py::arg("x0"), py::arg("x1"),
          py::arg("threads") = 1, py::arg("tolerance") = 1e-6, py::arg("max_iterations") = 1000000);
}
