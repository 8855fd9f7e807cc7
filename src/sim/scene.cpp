#include "tethash/sim/scene.hpp"
#include "tethash/detect_grammar.hpp"

#include "core/enum_names.hpp"

#include "tethash/error.hpp"
#include "tethash/io/mesh_io.hpp"

#include <toml++/toml.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <optional>
#include <sstream>
#include <vector>

namespace tethash::sim {

namespace {

/// The integrators' names, the canonical one first, then the aliases the parser also accepts.
constexpr tethash::detail::EnumName<Integrator> k_integrator_names[] = {
    {Integrator::symplectic_euler, "symplectic_euler"},
    {Integrator::symplectic_euler, "symplectic"},
    {Integrator::symplectic_euler, "explicit"},
    {Integrator::implicit_euler, "implicit_euler"},
    {Integrator::implicit_euler, "implicit"},
    {Integrator::vbd, "vbd"},
    {Integrator::vbd, "block_descent"},
};

constexpr tethash::detail::EnumName<LinearSolver> k_solver_names[] = {{LinearSolver::cg, "cg"},
                                                                      {LinearSolver::ldlt, "ldlt"}};

} // namespace

bool parse_seconds(const std::string& text, double& out)
{
    const auto number = [](const std::string& t, double& v) {
        if (t.empty() || std::isspace(static_cast<unsigned char>(t[0]))) return false;
        char* end = nullptr;
        v = std::strtod(t.c_str(), &end);
        return end == t.c_str() + t.size();
    };
    const std::size_t slash = text.find('/');
    if (slash == std::string::npos) return number(text, out);
    double a = 0, b = 0;
    if (!number(text.substr(0, slash), a) || !number(text.substr(slash + 1), b) || !(b != 0)) return false;
    out = a / b;
    return true;
}

Integrator parse_integrator(const std::string& name)
{
    if (const auto integrator = tethash::detail::value_named(k_integrator_names, name)) return *integrator;
    if (name == "local_global" || name == "liu" || name == "projective")
        throw Error("integrator '" + name +
                    "' was retired (it blew up on real meshes where implicit Euler held): use 'vbd', the default, "
                    "which solves the same implicit step by per-vertex Newton iterations");
    throw Error("integrator '" + name + "' unknown (vbd, implicit_euler, symplectic_euler)");
}

const char* to_string(Integrator integrator)
{
    return tethash::detail::name_of(k_integrator_names, integrator);
}

LinearSolver parse_linear_solver(const std::string& name)
{
    if (const auto solver = tethash::detail::value_named(k_solver_names, name)) return *solver;
    throw Error("solver '" + name + "' unknown (cg, ldlt)");
}

const char* to_string(LinearSolver solver)
{
    return tethash::detail::name_of(k_solver_names, solver);
}

namespace {

/// Largest lattice resolution of generated and tetrahedralized objects (meshing::generate's limit).
constexpr std::int64_t k_max_resolution = 1000;

/// Reads one TOML table, checking every key is known and every value has the right type.
class Reader {
  public:
    Reader(std::string source, std::string base_dir) : m_source(std::move(source)), m_base(std::move(base_dir)) {}

    [[noreturn]] void fail(const toml::node* node, const std::string& key, const std::string& what) const
    {
        std::string where = m_source;
        if (node && node->source().begin) where += ":" + std::to_string(node->source().begin.line);
        throw Error(where + ": key '" + key + "': " + what);
    }

    static const char* type_name(const toml::node& n)
    {
        static constexpr tethash::detail::EnumName<toml::node_type> names[] = {
            {toml::node_type::table, "a table"},           {toml::node_type::array, "an array"},
            {toml::node_type::string, "a string"},         {toml::node_type::integer, "an integer"},
            {toml::node_type::floating_point, "a number"}, {toml::node_type::boolean, "a boolean"},
        };
        return tethash::detail::name_of(names, n.type(), "a date/time");
    }

    /// Throws for keys of `tbl` not in `known`.
    void check_keys(const toml::table& tbl, const std::string& prefix, const std::vector<const char*>& known) const
    {
        for (auto&& [k, v] : tbl) {
            const std::string key(k.str());
            if (std::find_if(known.begin(), known.end(), [&](const char* s) { return key == s; }) != known.end())
                continue;
            std::string list;
            for (const char* s : known)
                list += (list.empty() ? "" : ", ") + std::string(s);
            std::string where = m_source;
            const auto& src = k.source().begin ? k.source() : v.source();
            if (src.begin) where += ":" + std::to_string(src.begin.line);
            throw Error(where + ": unknown key '" + prefix + key + "' (known here: " + list + ")");
        }
    }

    double number(const toml::node& n, const std::string& key) const
    {
        if (n.is_integer()) return static_cast<double>(*n.value<std::int64_t>());
        if (n.is_floating_point()) return *n.value<double>();
        fail(&n, key, std::string("expected a number, found ") + type_name(n));
    }
    double positive(const toml::node& n, const std::string& key) const
    {
        const double v = number(n, key);
        if (!(v > 0) || !std::isfinite(v)) fail(&n, key, "must be a positive finite number, found " + fmt(v));
        return v;
    }
    double non_negative(const toml::node& n, const std::string& key) const
    {
        const double v = number(n, key);
        if (!(v >= 0) || !std::isfinite(v)) fail(&n, key, "must be ≥ 0 and finite, found " + fmt(v));
        return v;
    }
    /// A time in seconds: a positive number, or a string with a number or a fraction such as "1/240" (the grammar of
    /// the command line's --dt).
    double seconds(const toml::node& n, const std::string& key) const
    {
        if (!n.is_string()) return positive(n, key);
        const std::string text = *n.value<std::string>();
        double v = 0;
        if (!parse_seconds(text, v) || !(v > 0) || !std::isfinite(v))
            fail(&n, key,
                 "must be a positive time in seconds: a number or a fraction such as \"1/240\", found \"" + text +
                     "\"");
        return v;
    }
    double fraction_below_one(const toml::node& n, const std::string& key) const
    {
        const double v = number(n, key);
        if (!(v >= 0 && v < 1)) fail(&n, key, "must be in [0, 1), found " + fmt(v));
        return v;
    }
    std::int64_t integer(const toml::node& n, const std::string& key) const
    {
        if (!n.is_integer()) fail(&n, key, std::string("expected an integer, found ") + type_name(n));
        return *n.value<std::int64_t>();
    }
    std::int64_t integer_at_least(const toml::node& n, const std::string& key, std::int64_t lo) const
    {
        const std::int64_t v = integer(n, key);
        if (v < lo) fail(&n, key, "must be ≥ " + std::to_string(lo) + ", found " + std::to_string(v));
        return v;
    }
    /// An integer in [lo, hi], checked before it is narrowed (4294967297 must not become 1).
    std::int64_t integer_in(const toml::node& n, const std::string& key, std::int64_t lo, std::int64_t hi) const
    {
        const std::int64_t v = integer(n, key);
        if (v < lo || v > hi)
            fail(&n, key,
                 "must be in [" + std::to_string(lo) + ", " + std::to_string(hi) + "], found " + std::to_string(v));
        return v;
    }
    /// An int in [lo, INT_MAX].
    int int_at_least(const toml::node& n, const std::string& key, int lo) const
    {
        return static_cast<int>(integer_in(n, key, lo, std::numeric_limits<int>::max()));
    }
    bool boolean(const toml::node& n, const std::string& key) const
    {
        if (!n.is_boolean()) fail(&n, key, std::string("expected true or false, found ") + type_name(n));
        return *n.value<bool>();
    }
    std::string string(const toml::node& n, const std::string& key) const
    {
        if (!n.is_string()) fail(&n, key, std::string("expected a string, found ") + type_name(n));
        return *n.value<std::string>();
    }
    Eigen::Vector3d vec3(const toml::node& n, const std::string& key) const
    {
        const toml::array* a = n.as_array();
        if (!a || a->size() != 3)
            fail(&n, key,
                 std::string("expected an array of 3 numbers, found ") +
                     (a ? "an array of " + std::to_string(a->size()) : type_name(n)));
        Eigen::Vector3d v;
        for (int i = 0; i < 3; ++i) {
            v[i] = number(*a->get(static_cast<size_t>(i)), key + "[" + std::to_string(i) + "]");
            if (!std::isfinite(v[i])) fail(&n, key, "must be finite");
        }
        return v;
    }
    const toml::table& table(const toml::node& n, const std::string& key) const
    {
        const toml::table* t = n.as_table();
        if (!t) fail(&n, key, std::string("expected a table, found ") + type_name(n));
        return *t;
    }
    std::string path(const std::string& p) const
    {
        std::filesystem::path fp(p);
        if (fp.is_absolute()) return p;
        return (std::filesystem::path(m_base) / fp).lexically_normal().string();
    }
    static std::string fmt(double v)
    {
        std::ostringstream s;
        s << v;
        return s.str();
    }

  private:
    std::string m_source, m_base;
};

/// One key of a TOML table and how its value is read into the struct T the table describes (key: the key as
/// messages name it).
template <class T> struct Key {
    const char* name;
    std::function<void(const Reader& r, const toml::node& value, const std::string& key, T& out)> read;
};

/// A key whose value one of Reader's checks (positive, non_negative, boolean, vec3, ...) reads into `field`.
template <class T, class F, class V>
Key<T> key(const char* name, F T::*field, V (Reader::*check)(const toml::node&, const std::string&) const)
{
    return {name, [field, check](const Reader& r, const toml::node& v, const std::string& k, T& out) {
                out.*field = (r.*check)(v, k);
            }};
}

/// A key whose value is an int ≥ lo, read into `field`.
template <class T> Key<T> int_key(const char* name, int T::*field, int lo)
{
    return {name, [field, lo](const Reader& r, const toml::node& v, const std::string& k, T& out) {
                out.*field = r.int_at_least(v, k, lo);
            }};
}

/// The keys of a penalty contact (the ground's, the objects' contacts): stiffness, damping and friction, each ≥ 0.
template <class T> std::vector<Key<T>> penalty_keys()
{
    return {key("stiffness", &T::stiffness, &Reader::non_negative), key("damping", &T::damping, &Reader::non_negative),
            key("friction", &T::friction, &Reader::non_negative)};
}

/// The keys `first`, then the keys `then`.
template <class T> std::vector<Key<T>> joined(std::vector<Key<T>> first, const std::vector<Key<T>>& then)
{
    first.insert(first.end(), then.begin(), then.end());
    return first;
}

/// Reads table `t` (its keys named `prefix` + key in messages) into `out` by `keys`. `more` are further keys
/// this table may have, which `other(key, value, prefix + key)` reads; any other key is an error.
template <class T, class Other>
void read_table(const Reader& r, const toml::table& t, const std::string& prefix, const std::vector<Key<T>>& keys,
                T& out, std::initializer_list<const char*> more, Other&& other)
{
    std::vector<const char*> known;
    for (const Key<T>& k : keys)
        known.push_back(k.name);
    known.insert(known.end(), more.begin(), more.end());
    r.check_keys(t, prefix, known);
    for (auto&& [k, v] : t) {
        const std::string name(k.str()), full = prefix + name;
        const auto it = std::find_if(keys.begin(), keys.end(), [&](const Key<T>& entry) { return name == entry.name; });
        if (it != keys.end())
            it->read(r, v, full, out);
        else
            other(name, v, full);
    }
}

template <class T>
void read_table(const Reader& r, const toml::table& t, const std::string& prefix, const std::vector<Key<T>>& keys,
                T& out)
{
    read_table(r, t, prefix, keys, out, {}, [](const std::string&, const toml::node&, const std::string&) {});
}

void read_material(const Reader& r, const toml::table& t, const std::string& pre, Material& m)
{
    static const std::vector<Key<Material>> keys = {
        key("density", &Material::density, &Reader::positive),
        key("stiffness", &Material::stiffness, &Reader::positive),
        key("young", &Material::young, &Reader::positive),
        key("damping", &Material::damping, &Reader::non_negative),
        key("volume_stiffness", &Material::volume_stiffness, &Reader::non_negative),
    };
    read_table(r, t, pre, keys, m);
}

ObjectSpec read_object(const Reader& r, const toml::table& t, const std::string& pre, size_t index)
{
    ObjectSpec o;
    o.name = "object " + std::to_string(index);
    r.check_keys(t, pre,
                 {"name", "mesh", "generate", "surface_resolution", "scale", "rotate", "translate", "velocity",
                  "material", "self_collision", "static", "collider"});
    for (auto&& [k, v] : t) {
        const std::string key(k.str()), full = pre + key;
        if (key == "name")
            o.name = r.string(v, full);
        else if (key == "mesh")
            o.mesh = r.path(r.string(v, full));
        else if (key == "surface_resolution")
            o.surface_resolution = static_cast<int>(r.integer_in(v, full, 1, k_max_resolution));
        else if (key == "scale") {
            if (v.is_number())
                o.scale.setConstant(r.positive(v, full));
            else
                o.scale = r.vec3(v, full);
            if (!(o.scale.minCoeff() > 0)) r.fail(&v, full, "must be positive");
        } else if (key == "rotate")
            o.rotate_deg = r.vec3(v, full);
        else if (key == "translate")
            o.translate = r.vec3(v, full);
        else if (key == "velocity")
            o.velocity = r.vec3(v, full);
        else if (key == "self_collision")
            o.self_collision = r.boolean(v, full);
        else if (key == "static")
            o.is_static = r.boolean(v, full);
        else if (key == "collider") {
            const std::string c = r.string(v, full);
            if (c == "bsp")
                o.collider = Collider::bsp;
            else if (c != "tets")
                r.fail(&v, full, "unknown collider '" + c + "' (known: tets, bsp)");
        } else if (key == "material")
            read_material(r, r.table(v, full), full + ".", o.material);
        else if (key == "generate") {
            const toml::table& g = r.table(v, full);
            r.check_keys(g, full + ".", {"shape", "resolution", "size", "snap"});
            meshing::GenerateParams gp;
            double longest = 0; // > 0 when 'size' is one number
            for (auto&& [gk, gv] : g) {
                const std::string gkey(gk.str()), gfull = full + "." + gkey;
                if (gkey == "shape") {
                    gp.shape = r.string(gv, gfull);
                    // Checked here so the message names the line; generate() checks again.
                    std::vector<std::string> shapes;
                    try {
                        shapes = meshing::generate_shapes();
                    } catch (const std::exception&) {
                    }
                    if (!shapes.empty() && std::find(shapes.begin(), shapes.end(), gp.shape) == shapes.end()) {
                        std::string list;
                        for (const auto& s : shapes)
                            list += (list.empty() ? "" : ", ") + s;
                        r.fail(&gv, gfull, "unknown shape '" + gp.shape + "' (known: " + list + ")");
                    }
                } else if (gkey == "resolution")
                    gp.resolution = static_cast<int>(r.integer_in(gv, gfull, 1, k_max_resolution));
                else if (gkey == "size") {
                    // A single number is the longest extent (the shape keeps its proportions);
                    // three numbers are the bounding-box extents (the shape is stretched to them).
                    if (gv.is_number())
                        longest = r.positive(gv, gfull);
                    else {
                        gp.size = r.vec3(gv, gfull);
                        if (!(gp.size.minCoeff() > 0)) r.fail(&gv, gfull, "must be positive");
                    }
                } else if (gkey == "snap")
                    gp.snap = r.boolean(gv, gfull);
            }
            if (longest > 0) gp.scale = longest / meshing::shape_natural_size(gp.shape).maxCoeff();
            o.generate = gp;
        }
    }
    if (o.mesh.empty() && !o.generate)
        r.fail(&t, pre.substr(0, pre.size() - 1), "an object needs 'mesh' or 'generate'");
    if (!o.mesh.empty() && o.generate)
        r.fail(&t, pre.substr(0, pre.size() - 1), "an object has either 'mesh' or 'generate', not both");
    if (o.collider == Collider::bsp &&
        (!o.is_static || o.mesh.empty() || io::classify_path(o.mesh) != io::PathKind::surface))
        r.fail(t.get("collider"), pre + "collider",
               "collider = \"bsp\" needs a static object (static = true) whose mesh is a closed surface file");
    return o;
}

/// The keys of [ground] and [contact].
const std::vector<Key<Ground>>& ground_keys()
{
    static const std::vector<Key<Ground>> keys = joined(
        {
            key("enabled", &Ground::enabled, &Reader::boolean),
            key("height", &Ground::height, &Reader::number),
            {"normal",
             [](const Reader& r, const toml::node& v, const std::string& k, Ground& g) {
                 g.normal = r.vec3(v, k);
                 if (!(g.normal.norm() > 0)) r.fail(&v, k, "must not be the zero vector");
                 g.normal.normalize();
             }},
        },
        penalty_keys<Ground>());
    return keys;
}

const std::vector<Key<ContactParams>>& contact_keys()
{
    static const std::vector<Key<ContactParams>> keys =
        joined(penalty_keys<ContactParams>(), {key("in_matrix", &ContactParams::in_matrix, &Reader::boolean),
                                               key("margin", &ContactParams::margin, &Reader::non_negative),
                                               key("speculative", &ContactParams::speculative, &Reader::boolean),
                                               key("edges", &ContactParams::edges, &Reader::boolean)});
    return keys;
}

/// The keys of the scene's top level; `up` receives the `up` key's axis (applied once the whole scene is read).
std::vector<Key<Scene>> scene_keys(std::optional<Eigen::Vector3d>& up)
{
    // Errors from the parameters' own grammar (integrator and solver names) name the key's line.
    const auto named = [](auto parse, auto field) {
        return [parse, field](const Reader& r, const toml::node& v, const std::string& k, Scene& out) {
            try {
                out.*field = parse(r.string(v, k));
            } catch (const Error& e) {
                r.fail(&v, k, e.what());
            }
        };
    };
    return {
        key("dt", &Scene::dt, &Reader::seconds),
        int_key("steps", &Scene::steps, 0),
        int_key("substeps", &Scene::substeps, 1),
        int_key("max_substeps", &Scene::max_substeps, 0),
        {"integrator", named(parse_integrator, &Scene::integrator)},
        {"solver", named(parse_linear_solver, &Scene::solver)},
        int_key("iterations", &Scene::iterations, 0),
        int_key("max_iterations", &Scene::max_iterations, 1),
        key("convergence", &Scene::convergence, &Reader::fraction_below_one),
        key("coarse_space", &Scene::coarse_space, &Reader::boolean),
        key("resume_retakes", &Scene::resume_retakes, &Reader::boolean),
        key("tolerance", &Scene::tolerance, &Reader::positive),
        key("sweep_tolerance", &Scene::sweep_tolerance, &Reader::non_negative),
        key("acceleration", &Scene::acceleration, &Reader::fraction_below_one),
        key("inversion_guard", &Scene::inversion_guard, &Reader::boolean),
        key("crossing_check", &Scene::crossing_check, &Reader::boolean),
        key("continuous_check", &Scene::continuous_check, &Reader::boolean),
        key("gravity", &Scene::gravity, &Reader::vec3),
        // The scene's up axis (applied by parse_scene): gravity 9.81 m/s² against it and the ground's normal along
        // it (meshes made with y up are common; the default is z up). A `gravity` or `[ground] normal` given too wins.
        {"up",
         [&up](const Reader& r, const toml::node& v, const std::string& k, Scene&) {
             const std::string name = r.string(v, k);
             const bool minus = !name.empty() && name[0] == '-';
             const std::string axis = minus ? name.substr(1) : name;
             if (axis != "x" && axis != "y" && axis != "z")
                 r.fail(&v, k, "expected \"x\", \"y\", \"z\" or one of them with a minus sign, found \"" + name + "\"");
             up = Eigen::Vector3d::Zero();
             (*up)[axis[0] - 'x'] = minus ? -1.0 : 1.0;
         }},
    };
}

/// One key of [detector]. Numbers are lengths or counts; strings go through the detector's own grammar
/// (detect_grammar.hpp), so a value means here what it means on the command line.
void read_detector_key(const Reader& r, const std::string& d, const toml::node& node, Scene& s)
{
    const std::string full = "detector." + d;
    const auto grammar = [&r, &node, &full](auto&& parse) {
        try {
            parse(r.string(node, full));
        } catch (const Error& e) {
            r.fail(&node, full, e.what());
        }
    };
    // A number (where a length or count is meant) is read by `number`, text by `parse`.
    const auto number_or_grammar = [&](auto&& number, auto&& parse) {
        if (node.is_number())
            number();
        else
            grammar(parse);
    };
    // The cell size and the skin: a number is an absolute length, text may give a factor instead.
    const auto length = [&](auto& mode, auto absolute, double& value,
                            double (Reader::*check)(const toml::node&, const std::string&) const,
                            void (*parse)(const std::string&, DetectParams&, const std::string&)) {
        number_or_grammar(
            [&] {
                mode = absolute;
                value = (r.*check)(node, full);
            },
            [&](const std::string& text) { parse(text, s.detect, full); });
    };
    if (d == "cell_size") {
        length(s.detect.cell_size_mode, DetectParams::CellSizeMode::absolute, s.detect.cell_size, &Reader::positive,
               parse_cell_size);
    } else if (d == "table_size") {
        number_or_grammar(
            [&] {
                s.detect.table_size = r.integer_at_least(node, full, 1);
                s.table_size_of_vertices.clear();
            },
            [&](const std::string& text) {
                // "auto", "N" or "xF" (F × the scene's vertex count, resolved when the scene is built)
                s.detect.table_size = parse_table_size(text, 0, full);
                s.table_size_of_vertices = text[0] == 'x' ? text : std::string();
            });
    } else if (d == "hash") {
        grammar([&](const std::string& text) { s.detect.hash = parse_hash_function(text); });
    } else if (d == "threads") {
        const long long threads = r.int_at_least(node, full, 0);
        try {
            s.detect.threads = check_threads(threads, full);
        } catch (const Error& e) {
            r.fail(&node, full, e.what());
        }
    } else if (d == "skin") { // candidate reuse: a length ≥ 0 (0 = off) or "xF" (F × cell size)
        length(s.detect.skin_mode, DetectParams::SkinMode::absolute, s.detect.skin, &Reader::non_negative, parse_skin);
    } else if (d == "method") { // the broad phase (detect_grammar.hpp: parse_method)
        grammar([&](const std::string& text) { s.detect.method = parse_method(text, full); });
    } else { // max_depth, leaf_size, looseness, levels: checked by the detector's own validation
        PartitionParams& q = s.detect.partition;
        if (d == "looseness")
            q.looseness = r.positive(node, full);
        else
            (d == "max_depth"   ? q.max_depth
             : d == "leaf_size" ? q.leaf_size
                                : q.levels) = static_cast<int>(r.int_at_least(node, full, 1));
        try {
            Detector check(s.detect);
        } catch (const Error& e) {
            r.fail(&node, full, e.what());
        }
    }
}

void read_detector(const Reader& r, const toml::table& t, Scene& s)
{
    r.check_keys(t, "detector.",
                 {"cell_size", "table_size", "hash", "threads", "skin", "method", "max_depth", "leaf_size", "looseness",
                  "levels"});
    for (auto&& [dk, dv] : t)
        read_detector_key(r, std::string(dk.str()), dv, s);
}

void read_output(const Reader& r, const toml::table& t, Scene& s)
{
    r.check_keys(t, "output.", {"every", "fields"});
    for (auto&& [ok, ov] : t) {
        const std::string o(ok.str()), full = "output." + o;
        if (o == "every")
            s.output.every = r.int_at_least(ov, full, 0);
        else if (o == "fields") {
            const toml::array* a = ov.as_array();
            if (!a) r.fail(&ov, full, std::string("expected an array of strings, found ") + Reader::type_name(ov));
            s.output.fields.clear();
            for (const toml::node& e : *a) {
                const std::string f = r.string(e, full);
                if (f != "velocity" && f != "contact" && f != "depth" && f != "object")
                    r.fail(&e, full, "unknown field '" + f + "' (velocity, contact, depth, object)");
                s.output.fields.push_back(f);
            }
        }
    }
}

/// [[pin]] number i (the table `t` of node `e`).
PinRegion read_pin(const Reader& r, const toml::node& e, const toml::table& t, size_t i)
{
    const std::string pre = "pin[" + std::to_string(i) + "].";
    PinRegion p;
    r.check_keys(t, pre, {"object", "vertices", "box_min", "box_max"});
    bool has_min = false, has_max = false;
    for (auto&& [pk, pv] : t) {
        const std::string pkey(pk.str()), full = pre + pkey;
        if (pkey == "object")
            p.object = r.int_at_least(pv, full, 0);
        else if (pkey == "vertices") {
            const toml::array* va = pv.as_array();
            if (!va) r.fail(&pv, full, std::string("expected an array of integers, found ") + Reader::type_name(pv));
            for (const toml::node& id : *va)
                p.vertices.push_back(r.int_at_least(id, full, 0));
        } else if (pkey == "box_min") {
            p.box_min = r.vec3(pv, full);
            has_min = true;
        } else if (pkey == "box_max") {
            p.box_max = r.vec3(pv, full);
            has_max = true;
        }
    }
    if (has_min != has_max) r.fail(&e, pre + (has_min ? "box_max" : "box_min"), "box_min and box_max go together");
    p.has_box = has_min;
    if (!p.has_box && p.vertices.empty())
        r.fail(&e, "pin[" + std::to_string(i) + "]", "a pin needs 'vertices' or 'box_min'/'box_max'");
    return p;
}

/// [[object]] and [[pin]]: arrays of tables.
void read_objects_or_pins(const Reader& r, const std::string& key, const toml::node& v, Scene& s)
{
    const toml::array* a = v.as_array();
    if (!a)
        r.fail(&v, key, std::string("expected an array of tables ([[") + key + "]]), found " + Reader::type_name(v));
    for (size_t i = 0; i < a->size(); ++i) {
        const toml::node& e = *a->get(i);
        const toml::table& t = r.table(e, key + "[" + std::to_string(i) + "]");
        if (key == "object")
            s.objects.push_back(read_object(r, t, key + "[" + std::to_string(i) + "].", i));
        else
            s.pins.push_back(read_pin(r, e, t, i));
    }
}

} // namespace

Scene parse_scene(const std::string& text, const std::string& source_name, const std::string& base_dir)
{
    toml::table root;
    try {
        root = toml::parse(text, source_name);
    } catch (const toml::parse_error& e) {
        throw Error(source_name + ":" + std::to_string(e.source().begin.line) + ":" +
                    std::to_string(e.source().begin.column) + ": TOML syntax: " + std::string(e.description()));
    }
    const Reader r(source_name, base_dir);
    Scene s;
    s.source = source_name;
    std::optional<Eigen::Vector3d> up;
    read_table(r, root, "", scene_keys(up), s, {"ground", "contact", "detector", "output", "object", "pin"},
               [&](const std::string& key, const toml::node& v, const std::string&) {
                   if (key == "ground") {
                       s.ground.enabled = true;
                       read_table(r, r.table(v, key), "ground.", ground_keys(), s.ground);
                   } else if (key == "contact") {
                       read_table(r, r.table(v, key), "contact.", contact_keys(), s.contact);
                   } else if (key == "detector") {
                       read_detector(r, r.table(v, key), s);
                   } else if (key == "output") {
                       read_output(r, r.table(v, key), s);
                   } else if (key == "object" || key == "pin") {
                       read_objects_or_pins(r, key, v, s);
                   }
               });
    for (size_t i = 0; i < s.pins.size(); ++i)
        if (s.pins[i].object >= static_cast<int>(s.objects.size()))
            throw Error(source_name + ": key 'pin[" + std::to_string(i) + "].object': object " +
                        std::to_string(s.pins[i].object) + " does not exist (" + std::to_string(s.objects.size()) +
                        " objects)");
    if (s.objects.empty()) throw Error(source_name + ": the scene has no [[object]]");
    // A scene file runs on every core unless it says otherwise: fewer in the steps where they do not pay
    // (simulation.hpp; the C++ Scene's own default stays one thread).
    const toml::table* detector = root["detector"].as_table();
    if (!detector || !detector->contains("threads")) s.detect.threads = 0;
    if (up) {
        if (!root.contains("gravity")) s.gravity = -9.81 * *up;
        const toml::table* ground = root["ground"].as_table();
        if (!ground || !ground->contains("normal")) s.ground.normal = *up;
    }
    return s;
}

Scene load_scene(const std::string& path)
{
    if (!std::filesystem::exists(path)) throw Error(path + ": no such scene file");
    if (std::filesystem::is_directory(path)) throw Error(path + ": is a directory, expected a scene file (.toml)");
    std::ifstream in(path, std::ios::binary);
    if (!in) throw Error(path + ": cannot open scene file");
    std::stringstream ss;
    ss << in.rdbuf();
    const std::string base = std::filesystem::path(path).parent_path().string();
    return parse_scene(ss.str(), path, base.empty() ? "." : base);
}

const std::string& default_scene_text()
{
    static const std::string text =
        R"(# tethash default scene: a soft bar, a ball and a ring dropped onto a static block and the ground.
dt = 2e-3
steps = 400
integrator = "vbd"
gravity = [0, 0, -9.81]

[ground]
height = 0.0
friction = 0.4

[output]
every = 5

[[object]]
name = "block"
generate = { shape = "box", resolution = 4, size = [1.2, 1.2, 0.4] }
translate = [0, 0, 0.2]
static = true

[[object]]
name = "bar"
generate = { shape = "bar", resolution = 12, size = [2.0, 0.3, 0.3] }
translate = [0.3, 0, 1.0]
rotate = [0, 0, 20]
material = { density = 500, young = 2e5, damping = 0.01 }

[[object]]
name = "ball"
generate = { shape = "sphere", resolution = 6, size = [0.5, 0.5, 0.5] }
translate = [-0.3, 0.2, 1.6]
velocity = [0.5, 0, 0]
material = { density = 300, young = 5e4 }

[[object]]
name = "ring"
generate = { shape = "torus", resolution = 10, size = [0.8, 0.8, 0.25] }
translate = [0.8, -0.5, 2.1]
rotate = [30, 0, 0]
material = { density = 400, young = 1e5 }
)";
    return text;
}

Scene default_scene()
{
    return parse_scene(default_scene_text(), "<default scene>", ".");
}

} // namespace tethash::sim
