// The C interface (include/tethash/tethash.h) over Detector, Penetration and the continuous queries: every entry point
// checks its pointers and sizes, runs the C++ call inside guard(), which maps exceptions to a status and a thread-local
// message, so nothing is thrown across the boundary.
#include "tethash/detect_grammar.hpp"
#include "tethash/tethash.h"

#include "tethash/ccd.hpp"
#include "tethash/continuous.hpp"
#include "tethash/detect.hpp"
#include "tethash/edge_contacts.hpp"
#include "tethash/error.hpp"
#include "tethash/penetration.hpp"

#include <cassert>
#include <cmath>
#include <cstddef>
#include <limits>
#include <new>
#include <string>
#include <vector>

#ifndef TETHASH_VERSION_STRING
#error "TETHASH_VERSION_STRING (the project version) is defined by CMakeLists.txt"
#endif

struct tethash_detector {
    tethash::Detector detector;
    tethash::Penetration penetration;
    bool penetration_ready = false; ///< penetration's topology is the detector's
    bool has_topology = false;
    // The topology as given, kept so that object options set later apply (set_topology is re-run).
    std::vector<tethash::Index> tets, vertex_object, tet_object;
    tethash::Index num_vertices = 0;
    std::vector<tethash::ObjectOptions> objects;
    tethash::DetectStats stats;
    bool detected = false; ///< contacts() belong to the current topology
    tethash::EdgeFaceDetector edges;
    bool edges_ready = false;                             ///< edges has the current topology and object options
    const tethash::EdgeFaceResult* edge_result = nullptr; ///< the last edge-face contacts of the current topology
    tethash::ccd::ContinuousDetector continuous_detector; ///< continuous detection, set up at its first call
    bool continuous_ready = false; ///< continuous_detector has the current topology and the locality rule below
    const tethash::ccd::ContinuousResult* continuous = nullptr; ///< the last continuous detection of the topology
    // The locality rule of continuous detection as given (empty: none): kept when object options re-apply the
    // topology, cleared by set_topology.
    std::vector<double> locality_rest, locality_reach_sq;
    std::vector<tethash::Index> locality_group;
};

namespace {

thread_local std::string last_error;

tethash_status fail(tethash_status status, const std::string& message)
{
    // Assigning may itself throw bad_alloc; the status is still returned.
    try {
        last_error = message;
    } catch (...) {
    }
    return status;
}

/// Runs `body` (returning a status), turning every exception into a status and a message prefixed by `where`.
template <class F> tethash_status guard(const char* where, F&& body) noexcept
{
    try {
        return body();
    } catch (const tethash::Error& e) {
        return fail(TETHASH_ERROR_INVALID_ARGUMENT, std::string(where) + ": " + e.what());
    } catch (const std::bad_alloc&) {
        return fail(TETHASH_ERROR_OUT_OF_MEMORY, std::string(where) + ": out of memory");
    } catch (const std::exception& e) {
        return fail(TETHASH_ERROR_INTERNAL, std::string(where) + ": " + e.what());
    } catch (...) {
        return fail(TETHASH_ERROR_INTERNAL, std::string(where) + ": unknown error");
    }
}

tethash_status null_argument(const char* where, const char* name)
{
    return fail(TETHASH_ERROR_NULL_ARGUMENT, std::string(where) + ": " + name + " is NULL");
}

tethash_status invalid(const char* where, const std::string& what)
{
    return fail(TETHASH_ERROR_INVALID_ARGUMENT, std::string(where) + ": " + what);
}

constexpr std::int64_t max_index = std::numeric_limits<tethash::Index>::max();

/// The continuous detector with the current topology and locality rule (set up when either changed).
tethash::ccd::ContinuousDetector& continuous_detector(tethash_detector& d)
{
    if (!d.continuous_ready) {
        const Eigen::Map<const tethash::Tets> tets(d.tets.data(), static_cast<Eigen::Index>(d.tets.size() / 4), 4);
        d.continuous_detector.set_topology(tets, d.num_vertices);
        if (!d.locality_reach_sq.empty()) {
            const Eigen::Map<const tethash::Positions> rest(d.locality_rest.data(),
                                                            static_cast<Eigen::Index>(d.num_vertices), 3);
            d.continuous_detector.set_locality(rest, d.locality_group, d.locality_reach_sq);
        }
        d.continuous_ready = true;
    }
    return d.continuous_detector;
}

/// Re-applies the stored topology with the current object options.
void apply_topology(tethash_detector& d)
{
    const Eigen::Map<const tethash::Tets> tets(d.tets.data(), static_cast<Eigen::Index>(d.tets.size() / 4), 4);
    d.detected = false;
    d.penetration_ready = false;
    d.has_topology = false;
    d.edges_ready = false;
    d.edge_result = nullptr;
    d.continuous = nullptr;
    d.continuous_ready = false;
    d.detector.set_topology(tets, d.num_vertices, d.vertex_object, d.tet_object, d.objects);
    d.has_topology = true;
}

tethash_contact to_c(const tethash::Contact& c)
{
    tethash_contact o;
    o.vertex = c.vertex;
    o.tet = c.tet;
    o.vertex_object = c.vertex_object;
    o.tet_object = c.tet_object;
    for (int k = 0; k < 4; ++k)
        o.bary[k] = c.bary[k];
    o.depth = c.depth;
    for (int k = 0; k < 3; ++k)
        o.direction[k] = c.direction[k];
    return o;
}

/// Sets one parameter through set_params (validated there); restores nothing on failure (set_params validates
/// before it changes anything).
template <class F> tethash_status set_param(tethash_detector* d, const char* where, F&& change)
{
    if (!d) return null_argument(where, "detector");
    return guard(where, [&] {
        tethash::DetectParams p = d->detector.params();
        change(p);
        d->detector.set_params(p);
        return TETHASH_OK;
    });
}

/// The checks of a call that passes positions to a detector: `ready` (a topology, or a detection, per
/// `not_ready`'s message), then `positions` for the topology's vertices. TETHASH_OK when the call may go on.
tethash_status check_positions(const char* where, const tethash_detector* d, bool tethash_detector::*ready,
                               const char* not_ready, const double* positions, int64_t num_vertices)
{
    if (!d) return null_argument(where, "detector");
    if (!(d->*ready)) return fail(TETHASH_ERROR_STATE, std::string(where) + ": " + not_ready);
    if (num_vertices != d->num_vertices)
        return invalid(where, "num_vertices is " + std::to_string(num_vertices) + ", the topology has " +
                                  std::to_string(d->num_vertices));
    if (!positions && num_vertices > 0) return null_argument(where, "positions");
    return TETHASH_OK;
}

/// The continuous queries' shared checks and call; `edge_edge` picks the query.
tethash_status ccd_query(const char* where, bool edge_edge, const double* start, const double* end, double tolerance,
                         std::int64_t max_iterations, std::int32_t* out_hit, double* out_toi)
{
    if (!start) return null_argument(where, "start");
    if (!end) return null_argument(where, "end");
    if (!out_hit) return null_argument(where, "out_hit");
    if (!out_toi) return null_argument(where, "out_toi");
    return guard(where, [&] {
        using V = Eigen::Vector3d;
        const auto s = [&](int i) { return V(start[3 * i], start[3 * i + 1], start[3 * i + 2]); };
        const auto e = [&](int i) { return V(end[3 * i], end[3 * i + 1], end[3 * i + 2]); };
        tethash::ccd::CcdParams params;
        params.tolerance = tolerance;
        params.max_iterations = max_iterations;
        const tethash::ccd::CcdResult r =
            edge_edge ? tethash::ccd::edge_edge_ccd(s(0), s(1), s(2), s(3), e(0), e(1), e(2), e(3), params)
                      : tethash::ccd::vertex_face_ccd(s(0), s(1), s(2), s(3), e(0), e(1), e(2), e(3), params);
        *out_hit = r.hit ? 1 : 0;
        *out_toi = r.toi;
        return TETHASH_OK;
    });
}

} // namespace

extern "C" {

const char* tethash_last_error(void)
{
    return last_error.c_str();
}

const char* tethash_version(void)
{
    return TETHASH_VERSION_STRING;
}

tethash_status tethash_detector_create(tethash_detector** out_detector)
{
    const char* where = "tethash_detector_create";
    if (!out_detector) return null_argument(where, "out_detector");
    *out_detector = nullptr;
    return guard(where, [&] {
        *out_detector = new tethash_detector();
        return TETHASH_OK;
    });
}

void tethash_detector_destroy(tethash_detector* detector)
{
    delete detector;
}

tethash_status tethash_detector_set_cell_size(tethash_detector* detector, int32_t mode, double value)
{
    const char* where = "tethash_detector_set_cell_size";
    if (mode != TETHASH_CELL_SIZE_AUTO && mode != TETHASH_CELL_SIZE_ABSOLUTE && mode != TETHASH_CELL_SIZE_FACTOR)
        return invalid(where, "unknown mode " + std::to_string(mode));
    if (mode != TETHASH_CELL_SIZE_AUTO && !(std::isfinite(value) && value > 0))
        return invalid(where, "value must be finite and > 0, got " + std::to_string(value));
    return set_param(detector, where, [&](tethash::DetectParams& p) {
        using M = tethash::DetectParams::CellSizeMode;
        p.cell_size_mode = mode == TETHASH_CELL_SIZE_AUTO       ? M::auto_mean_edge
                           : mode == TETHASH_CELL_SIZE_ABSOLUTE ? M::absolute
                                                                : M::factor_of_mean_edge;
        if (mode != TETHASH_CELL_SIZE_AUTO) p.cell_size = value;
    });
}

tethash_status tethash_detector_set_table_size(tethash_detector* detector, int64_t buckets)
{
    const char* where = "tethash_detector_set_table_size";
    if (buckets < 0) return invalid(where, "buckets must be ≥ 0 (0 = automatic), got " + std::to_string(buckets));
    return set_param(detector, where, [&](tethash::DetectParams& p) { p.table_size = buckets; });
}

tethash_status tethash_detector_set_threads(tethash_detector* detector, int32_t threads)
{
    const char* where = "tethash_detector_set_threads";
    if (!detector) return null_argument(where, "detector");
    return guard(where, [&] {
        const int checked = tethash::check_threads(threads, "threads");
        return set_param(detector, where, [&](tethash::DetectParams& p) { p.threads = checked; });
    });
}

tethash_status tethash_detector_set_hash(tethash_detector* detector, int32_t hash)
{
    const char* where = "tethash_detector_set_hash";
    if (hash != TETHASH_HASH_COLUMN && hash != TETHASH_HASH_TESCHNER)
        return invalid(where, "unknown hash " + std::to_string(hash));
    return set_param(detector, where, [&](tethash::DetectParams& p) {
        p.hash = hash == TETHASH_HASH_COLUMN ? tethash::HashFunction::column : tethash::HashFunction::teschner;
    });
}

tethash_status tethash_detector_set_skin(tethash_detector* detector, double skin)
{
    const char* where = "tethash_detector_set_skin";
    if (!(std::isfinite(skin) && skin >= 0))
        return invalid(where, "skin must be finite and ≥ 0, got " + std::to_string(skin));
    return set_param(detector, where, [&](tethash::DetectParams& p) {
        p.skin_mode = tethash::DetectParams::SkinMode::absolute;
        p.skin = skin;
    });
}

tethash_status tethash_detector_set_object_options(tethash_detector* detector, int32_t object, int32_t self_collision,
                                                   int32_t is_static)
{
    const char* where = "tethash_detector_set_object_options";
    if (!detector) return null_argument(where, "detector");
    if (object < 0 || object >= (1 << 20))
        return invalid(where, "object must be in [0, 1048576), got " + std::to_string(object));
    return guard(where, [&] {
        auto& objects = detector->objects;
        const std::vector<tethash::ObjectOptions> before = objects;
        if (static_cast<std::size_t>(object) >= objects.size()) objects.resize(static_cast<std::size_t>(object) + 1);
        objects[static_cast<std::size_t>(object)].self_collision = self_collision != 0;
        objects[static_cast<std::size_t>(object)].is_static = is_static != 0;
        if (detector->has_topology) {
            try {
                apply_topology(*detector);
            } catch (...) {
                objects = before;
                apply_topology(*detector);
                throw;
            }
        }
        return TETHASH_OK;
    });
}

tethash_status tethash_detector_set_topology(tethash_detector* detector, const int32_t* tets, int64_t num_tets,
                                             int64_t num_vertices, const int32_t* vertex_object,
                                             const int32_t* tet_object)
{
    const char* where = "tethash_detector_set_topology";
    if (!detector) return null_argument(where, "detector");
    if (num_tets < 0 || num_tets > max_index)
        return invalid(where,
                       "num_tets must be in [0, " + std::to_string(max_index) + "], got " + std::to_string(num_tets));
    if (num_vertices < 0 || num_vertices > max_index)
        return invalid(where, "num_vertices must be in [0, " + std::to_string(max_index) + "], got " +
                                  std::to_string(num_vertices));
    if (!tets && num_tets > 0) return null_argument(where, "tets");
    return guard(where, [&] {
        tethash_detector& d = *detector;
        const auto m = static_cast<std::size_t>(num_tets), n = static_cast<std::size_t>(num_vertices);
        std::vector<tethash::Index> t;
        if (tets) t.assign(tets, tets + 4 * m);
        std::vector<tethash::Index> vo, to;
        if (vertex_object) vo.assign(vertex_object, vertex_object + n);
        if (tet_object) to.assign(tet_object, tet_object + m);
        // The detector validates indices and object ids; on failure the previous arrays are restored and the
        // detector is left without a topology (detect then answers TETHASH_ERROR_STATE).
        d.tets.swap(t);
        d.vertex_object.swap(vo);
        d.tet_object.swap(to);
        const tethash::Index old_n = d.num_vertices;
        d.num_vertices = static_cast<tethash::Index>(num_vertices);
        try {
            apply_topology(d);
        } catch (...) {
            d.tets.swap(t);
            d.vertex_object.swap(vo);
            d.tet_object.swap(to);
            d.num_vertices = old_n;
            d.has_topology = false;
            throw;
        }
        d.locality_rest.clear();
        d.locality_reach_sq.clear();
        d.locality_group.clear();
        return TETHASH_OK;
    });
}

tethash_status tethash_detector_detect(tethash_detector* detector, const double* positions, int64_t num_vertices,
                                       int64_t* out_count)
{
    const char* where = "tethash_detector_detect";
    if (out_count) *out_count = 0;
    if (const tethash_status s = check_positions(where, detector, &tethash_detector::has_topology, "no topology set",
                                                 positions, num_vertices);
        s != TETHASH_OK)
        return s;
    return guard(where, [&] {
        detector->detected = false;
        const Eigen::Map<const tethash::Positions> map(positions, static_cast<Eigen::Index>(num_vertices), 3);
        const tethash::PositionsRef p(map);
        assert(p.data() == positions); // the caller's array, read in place
        const auto& contacts = detector->detector.detect(p, &detector->stats);
        detector->detected = true;
        if (out_count) *out_count = static_cast<int64_t>(contacts.size());
        return TETHASH_OK;
    });
}

tethash_status tethash_detector_contact_count(const tethash_detector* detector, int64_t* out_count)
{
    const char* where = "tethash_detector_contact_count";
    if (!detector) return null_argument(where, "detector");
    if (!out_count) return null_argument(where, "out_count");
    auto& d = const_cast<tethash_detector&>(*detector);
    *out_count = d.detected ? static_cast<int64_t>(d.detector.contacts().size()) : 0;
    return TETHASH_OK;
}

tethash_status tethash_detector_contact(const tethash_detector* detector, int64_t i, tethash_contact* out_contact)
{
    const char* where = "tethash_detector_contact";
    if (!detector) return null_argument(where, "detector");
    if (!out_contact) return null_argument(where, "out_contact");
    auto& d = const_cast<tethash_detector&>(*detector);
    const int64_t count = d.detected ? static_cast<int64_t>(d.detector.contacts().size()) : 0;
    if (i < 0 || i >= count)
        return invalid(where, "contact " + std::to_string(i) + " out of range [0, " + std::to_string(count) + ")");
    *out_contact = to_c(d.detector.contacts()[static_cast<std::size_t>(i)]);
    return TETHASH_OK;
}

tethash_status tethash_detector_get_contacts(const tethash_detector* detector, int64_t capacity, int32_t* vertex,
                                             int32_t* tet, double* bary, double* depth, double* direction)
{
    const char* where = "tethash_detector_get_contacts";
    if (!detector) return null_argument(where, "detector");
    auto& d = const_cast<tethash_detector&>(*detector);
    const std::size_t count = d.detected ? d.detector.contacts().size() : 0;
    if (capacity < 0 || static_cast<std::size_t>(capacity) < count)
        return invalid(where, "capacity " + std::to_string(capacity) + " is less than the " + std::to_string(count) +
                                  " contacts");
    const std::vector<tethash::Contact>& cs = d.detector.contacts();
    for (std::size_t i = 0; i < count; ++i) {
        const tethash::Contact& c = cs[i];
        if (vertex) vertex[i] = c.vertex;
        if (tet) tet[i] = c.tet;
        if (bary)
            for (std::size_t k = 0; k < 4; ++k)
                bary[4 * i + k] = c.bary[k];
        if (depth) depth[i] = c.depth;
        if (direction)
            for (std::size_t k = 0; k < 3; ++k)
                direction[3 * i + k] = c.direction[k];
    }
    return TETHASH_OK;
}

tethash_status tethash_detector_compute_penetration(tethash_detector* detector, const double* positions,
                                                    int64_t num_vertices)
{
    const char* where = "tethash_detector_compute_penetration";
    if (const tethash_status s = check_positions(where, detector, &tethash_detector::detected,
                                                 "no detection to complete", positions, num_vertices);
        s != TETHASH_OK)
        return s;
    return guard(where, [&] {
        tethash_detector& d = *detector;
        if (!d.penetration_ready) {
            const Eigen::Map<const tethash::Tets> tets(d.tets.data(), static_cast<Eigen::Index>(d.tets.size() / 4), 4);
            d.penetration.set_topology(tets, d.num_vertices, d.vertex_object, d.tet_object);
            d.penetration_ready = true;
        }
        const Eigen::Map<const tethash::Positions> p(positions, static_cast<Eigen::Index>(num_vertices), 3);
        for (Eigen::Index v = 0; v < p.rows(); ++v)
            if (!p.row(v).allFinite())
                return invalid(where, "position of vertex " + std::to_string(v) + " is not finite");
        d.penetration.compute(p, d.detector.contacts());
        return TETHASH_OK;
    });
}

tethash_status tethash_detector_stats(const tethash_detector* detector, tethash_stats* out_stats)
{
    const char* where = "tethash_detector_stats";
    if (!detector) return null_argument(where, "detector");
    if (!out_stats) return null_argument(where, "out_stats");
    const tethash::DetectStats& s = detector->stats;
    out_stats->ms_total = s.ms_total;
    out_stats->cell_size = s.cell_size;
    out_stats->table_size = s.table_size;
    out_stats->contacts = s.contacts;
    out_stats->reused = s.reused;
    out_stats->threads = s.threads;
    return TETHASH_OK;
}

tethash_status tethash_detector_find_edge_contacts(tethash_detector* detector, const double* positions,
                                                   int64_t num_vertices, int64_t* out_count)
{
    const char* where = "tethash_detector_find_edge_contacts";
    if (out_count) *out_count = 0;
    if (const tethash_status s = check_positions(where, detector, &tethash_detector::has_topology, "no topology set",
                                                 positions, num_vertices);
        s != TETHASH_OK)
        return s;
    return guard(where, [&] {
        tethash_detector& d = *detector;
        d.edge_result = nullptr;
        if (!d.edges_ready) {
            const Eigen::Map<const tethash::Tets> tets(d.tets.data(), static_cast<Eigen::Index>(d.tets.size() / 4), 4);
            d.edges.set_topology(tets, d.num_vertices, d.vertex_object, d.tet_object, d.objects);
            d.edges_ready = true;
        }
        const Eigen::Map<const tethash::Positions> map(positions, static_cast<Eigen::Index>(num_vertices), 3);
        d.edge_result = &d.edges.find(map, d.detector.params().threads);
        if (out_count) *out_count = static_cast<int64_t>(d.edge_result->contacts.size());
        return TETHASH_OK;
    });
}

tethash_status tethash_detector_get_edge_contacts(const tethash_detector* detector, int64_t capacity, int32_t* edge,
                                                  int32_t* face, int32_t* objects, double* t, double* face_bary,
                                                  int32_t* inner_end, double* normal)
{
    const char* where = "tethash_detector_get_edge_contacts";
    if (!detector) return null_argument(where, "detector");
    const std::size_t count = detector->edge_result ? detector->edge_result->contacts.size() : 0;
    if (capacity < 0 || static_cast<std::size_t>(capacity) < count)
        return invalid(where, "capacity " + std::to_string(capacity) + " is less than the " + std::to_string(count) +
                                  " edge-face contacts");
    for (std::size_t i = 0; i < count; ++i) {
        const tethash::EdgeFaceContact& c = detector->edge_result->contacts[i];
        for (std::size_t k = 0; k < 3; ++k) {
            if (edge && k < 2) edge[2 * i + k] = c.edge_vertices[k];
            if (face) face[3 * i + k] = c.face_vertices[k];
            if (face_bary) face_bary[3 * i + k] = c.face_bary[k];
            if (normal) normal[3 * i + k] = c.normal[k];
        }
        if (objects) {
            objects[2 * i] = c.edge_object;
            objects[2 * i + 1] = c.face_object;
        }
        if (t) t[i] = c.edge_t;
        if (inner_end) inner_end[i] = c.inner_end;
    }
    return TETHASH_OK;
}

tethash_status tethash_detector_detect_continuous(tethash_detector* detector, const double* start, const double* end,
                                                  int64_t num_vertices, double tolerance, int64_t max_iterations,
                                                  int64_t* out_count)
{
    const char* where = "tethash_detector_detect_continuous";
    if (out_count) *out_count = 0;
    if (const tethash_status s =
            check_positions(where, detector, &tethash_detector::has_topology, "no topology set", start, num_vertices);
        s != TETHASH_OK)
        return s;
    if (!end && num_vertices > 0) return null_argument(where, "end");
    return guard(where, [&] {
        tethash_detector& d = *detector;
        d.continuous = nullptr;
        const Eigen::Map<const tethash::Positions> x0(start, static_cast<Eigen::Index>(num_vertices), 3);
        const Eigen::Map<const tethash::Positions> x1(end, static_cast<Eigen::Index>(num_vertices), 3);
        tethash::ccd::ContinuousParams params;
        params.query.tolerance = tolerance;
        params.query.max_iterations = max_iterations;
        params.threads = d.detector.params().threads;
        d.continuous = &continuous_detector(d).detect(x0, x1, params);
        if (out_count) *out_count = static_cast<int64_t>(d.continuous->contacts.size());
        return TETHASH_OK;
    });
}

tethash_status tethash_detector_set_continuous_locality(tethash_detector* detector, const double* rest,
                                                        int64_t num_vertices, const int32_t* vertex_group,
                                                        const double* reach_sq, int64_t num_groups)
{
    const char* where = "tethash_detector_set_continuous_locality";
    if (!detector) return null_argument(where, "detector");
    if (!detector->has_topology) return fail(TETHASH_ERROR_STATE, std::string(where) + ": no topology set");
    if (num_vertices != detector->num_vertices)
        return invalid(where, "num_vertices is " + std::to_string(num_vertices) + ", the topology has " +
                                  std::to_string(detector->num_vertices));
    if (num_groups < 0 || num_groups > max_index)
        return invalid(where, "num_groups must be in [0, " + std::to_string(max_index) + "], got " +
                                  std::to_string(num_groups));
    if (num_groups > 0 && !rest && num_vertices > 0) return null_argument(where, "rest");
    if (num_groups > 0 && !vertex_group && num_vertices > 0) return null_argument(where, "vertex_group");
    if (num_groups > 0 && !reach_sq) return null_argument(where, "reach_sq");
    return guard(where, [&] {
        tethash_detector& d = *detector;
        const auto n = static_cast<std::size_t>(num_vertices), g = static_cast<std::size_t>(num_groups);
        std::vector<double> r, q;
        std::vector<tethash::Index> v;
        if (g > 0) {
            if (n > 0) {
                r.assign(rest, rest + 3 * n);
                v.assign(vertex_group, vertex_group + n);
            }
            q.assign(reach_sq, reach_sq + g);
        }
        // The continuous detector validates (naming the entry); on failure the rule before is kept.
        d.continuous = nullptr;
        continuous_detector(d);
        if (g > 0) {
            const Eigen::Map<const tethash::Positions> x(r.data(), static_cast<Eigen::Index>(n), 3);
            try {
                d.continuous_detector.set_locality(x, v, q);
            } catch (...) {
                d.continuous_ready = false;
                throw;
            }
        } else {
            d.continuous_ready = false;
        }
        d.locality_rest.swap(r);
        d.locality_group.swap(v);
        d.locality_reach_sq.swap(q);
        return TETHASH_OK;
    });
}

tethash_status tethash_detector_continuous_broad_phase_pairs(const tethash_detector* detector, int64_t* out_pairs)
{
    const char* where = "tethash_detector_continuous_broad_phase_pairs";
    if (!detector) return null_argument(where, "detector");
    if (!out_pairs) return null_argument(where, "out_pairs");
    *out_pairs = detector->continuous ? detector->continuous->broad_phase_pairs : 0;
    return TETHASH_OK;
}

tethash_status tethash_detector_get_continuous_contacts(const tethash_detector* detector, int64_t capacity,
                                                        int32_t* kind, int32_t* vertices, double* toi)
{
    const char* where = "tethash_detector_get_continuous_contacts";
    if (!detector) return null_argument(where, "detector");
    static const tethash::ccd::ContinuousResult none;
    const tethash::ccd::ContinuousResult& r = detector->continuous ? *detector->continuous : none;
    const std::size_t count = r.contacts.size();
    if (capacity < 0 || static_cast<std::size_t>(capacity) < count)
        return invalid(where, "capacity " + std::to_string(capacity) + " is less than the " + std::to_string(count) +
                                  " continuous contacts");
    for (std::size_t i = 0; i < count; ++i) {
        const tethash::ccd::ContinuousContact& c = r.contacts[i];
        const bool vf = c.kind == tethash::ccd::ContinuousKind::vertex_face;
        if (kind) kind[i] = vf ? 0 : 1;
        if (toi) toi[i] = c.toi;
        if (!vertices) continue;
        std::int32_t* row = vertices + 4 * i;
        if (vf) {
            row[0] = static_cast<std::int32_t>(c.a);
            for (Eigen::Index k = 0; k < 3; ++k)
                row[1 + k] = static_cast<std::int32_t>(r.faces(c.b, k));
        } else {
            for (Eigen::Index k = 0; k < 2; ++k) {
                row[k] = static_cast<std::int32_t>(r.edges(c.a, k));
                row[2 + k] = static_cast<std::int32_t>(r.edges(c.b, k));
            }
        }
    }
    return TETHASH_OK;
}

tethash_status tethash_ccd_vertex_face(const double* start, const double* end, double tolerance, int64_t max_iterations,
                                       int32_t* out_hit, double* out_toi)
{
    return ccd_query("tethash_ccd_vertex_face", false, start, end, tolerance, max_iterations, out_hit, out_toi);
}

tethash_status tethash_ccd_edge_edge(const double* start, const double* end, double tolerance, int64_t max_iterations,
                                     int32_t* out_hit, double* out_toi)
{
    return ccd_query("tethash_ccd_edge_edge", true, start, end, tolerance, max_iterations, out_hit, out_toi);
}

} // extern "C"
