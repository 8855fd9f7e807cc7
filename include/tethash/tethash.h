/* tethash.h: the C interface of the detector (tethash::core), for C, Fortran (iso_c_binding) and any language
 * with a C foreign-function interface.
 *
 * - Opaque handle: tethash_detector, made by tethash_detector_create and freed by tethash_detector_destroy.
 * - Every function returns a tethash_status (TETHASH_OK = 0); on failure, tethash_last_error() gives a message
 *   naming the function, the argument and the value. The message is per thread and kept until the next failing
 *   call on that thread. No C++ exception crosses this interface.
 * - Arrays are the caller's, row-major, 0-based indices: positions n x 3 doubles (x0 y0 z0 x1 ...), tets m x 4
 *   int32. A Fortran array real(c_double) :: x(3, n) or integer(c_int32_t) :: tets(4, m) has this layout.
 * - tethash_detector_detect reads the caller's positions in place (no copy); the topology is copied once by
 *   tethash_detector_set_topology.
 *
 * Typical use:
 *     tethash_detector* d = NULL;
 *     tethash_detector_create(&d);
 *     tethash_detector_set_topology(d, tets, m, n, NULL, NULL);      // once
 *     for each step / Newton iteration:
 *         int64_t count;
 *         if (tethash_detector_detect(d, xyz, n, &count) != TETHASH_OK) puts(tethash_last_error());
 *         tethash_detector_get_contacts(d, count, vertex, tet, bary, NULL, NULL);
 *     tethash_detector_destroy(d);
 */
#ifndef TETHASH_TETHASH_H
#define TETHASH_TETHASH_H

#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

/** Status of every call. */
typedef enum tethash_status {
    TETHASH_OK = 0,
    TETHASH_ERROR_NULL_ARGUMENT = 1,    /**< a required pointer was NULL */
    TETHASH_ERROR_INVALID_ARGUMENT = 2, /**< a value out of range: index, size, parameter, non-finite position */
    TETHASH_ERROR_STATE = 3,            /**< call out of order (detect before set_topology, ...) */
    TETHASH_ERROR_OUT_OF_MEMORY = 4,
    TETHASH_ERROR_INTERNAL = 5 /**< anything else (a bug: please report the message) */
} tethash_status;

/** How tethash_detector_set_cell_size reads its value. */
typedef enum tethash_cell_size_mode {
    TETHASH_CELL_SIZE_AUTO = 0,     /**< the mean edge length (value ignored; the default) */
    TETHASH_CELL_SIZE_ABSOLUTE = 1, /**< value is the cell edge length (> 0) */
    TETHASH_CELL_SIZE_FACTOR = 2    /**< value (> 0) times the mean edge length */
} tethash_cell_size_mode;

/** Hash function of the grid cells (see detect.hpp). */
typedef enum tethash_hash { TETHASH_HASH_COLUMN = 0, TETHASH_HASH_TESCHNER = 1 } tethash_hash;

/** One contact: vertex `vertex` lies inside (or on) tet `tet`. Depth and direction are NaN and 0 unless
 *  tethash_detector_compute_penetration ran after the detection. */
typedef struct tethash_contact {
    int32_t vertex, tet;
    int32_t vertex_object, tet_object;
    double bary[4];      /**< barycentric coordinates of the vertex in the tet */
    double depth;        /**< penetration depth (length units, >= 0) */
    double direction[3]; /**< unit vector out of the penetrated object */
} tethash_contact;

/** A few statistics of the last detection. Times in milliseconds. */
typedef struct tethash_stats {
    double ms_total;
    double cell_size;   /**< cell edge length used */
    int64_t table_size; /**< buckets used */
    int64_t contacts;   /**< contacts found */
    int32_t reused;     /**< 1 when the skin's kept candidates were reused (stages 1-2 skipped) */
    int32_t threads;    /**< threads used */
} tethash_stats;

typedef struct tethash_detector tethash_detector;

/** Message of the last failing call on this thread ("" if none). Valid until the next failing call. */
const char* tethash_last_error(void);
/** Library version, "MAJOR.MINOR.PATCH". */
const char* tethash_version(void);

/** Creates a detector with the default parameters (automatic cell and table size, all threads, no skin). */
tethash_status tethash_detector_create(tethash_detector** out_detector);
/** Frees the detector (NULL is accepted and ignored). */
void tethash_detector_destroy(tethash_detector* detector);

/* ---- parameters: each may be set at any time; validated when set ---- */
/** `mode`: a tethash_cell_size_mode. Enumerations are passed as int32_t (an out-of-range value is an error, and
 *  the size is the same for every compiler and for Fortran). */
tethash_status tethash_detector_set_cell_size(tethash_detector* detector, int32_t mode, double value);
/** Number of buckets, >= 1; 0 = automatic. */
tethash_status tethash_detector_set_table_size(tethash_detector* detector, int64_t buckets);
/** 0 = every hardware thread (the default), 1 = serial, up to the machine's limit. */
tethash_status tethash_detector_set_threads(tethash_detector* detector, int32_t threads);
/** `hash`: a tethash_hash. */
tethash_status tethash_detector_set_hash(tethash_detector* detector, int32_t hash);
/** Candidate reuse between calls (a length >= 0; 0 = off): see DetectParams::skin in detect.hpp. */
tethash_status tethash_detector_set_skin(tethash_detector* detector, double skin);
/** Options of object `object` (0 <= object < 2^20): contacts within the object (self_collision != 0, the default) and
 * static objects (is_static != 0: positions never change). Kept across set_topology calls. */
tethash_status tethash_detector_set_object_options(tethash_detector* detector, int32_t object, int32_t self_collision,
                                                   int32_t is_static);

/* ---- topology: once, before detecting ---- */
/** `tets`: num_tets x 4 vertex indices in [0, num_vertices). `vertex_object` (num_vertices entries) and
 *  `tet_object` (num_tets entries) give object ids >= 0; NULL: all 0. Copied. */
tethash_status tethash_detector_set_topology(tethash_detector* detector, const int32_t* tets, int64_t num_tets,
                                             int64_t num_vertices, const int32_t* vertex_object,
                                             const int32_t* tet_object);

/* ---- per step ---- */
/** Detects on `positions` (num_vertices x 3, num_vertices as in set_topology), read in place. Writes the number of
 *  contacts to `out_count` (may be NULL). The contacts stay readable until the next detect or set_topology. */
tethash_status tethash_detector_detect(tethash_detector* detector, const double* positions, int64_t num_vertices,
                                       int64_t* out_count);
/** Number of contacts of the last detection (0 before any). */
tethash_status tethash_detector_contact_count(const tethash_detector* detector, int64_t* out_count);
/** Contact `i` (0 <= i < count) of the last detection, sorted by (vertex, tet). */
tethash_status tethash_detector_contact(const tethash_detector* detector, int64_t i, tethash_contact* out_contact);
/** Copies the contacts of the last detection into caller arrays of `capacity` rows, each may be NULL: vertex and tet
 *  (capacity entries), bary (capacity x 4), depth (capacity), direction (capacity x 3). `capacity` must be at least
 *  the contact count. */
tethash_status tethash_detector_get_contacts(const tethash_detector* detector, int64_t capacity, int32_t* vertex,
                                             int32_t* tet, double* bary, double* depth, double* direction);
/** Fills depth and direction of the last detection's contacts (Heidelberger et al. 2004, penetration.hpp), at
 *  `positions` (the same array and values as the detection). */
tethash_status tethash_detector_compute_penetration(tethash_detector* detector, const double* positions,
                                                    int64_t num_vertices);
/** Statistics of the last detection. */
tethash_status tethash_detector_stats(const tethash_detector* detector, tethash_stats* out_stats);

/** Edge-face contacts (edge_contacts.hpp): boundary edges crossing a boundary triangle of another object, or of a
 *  distant part of their own (no vertex of the edge and of the triangle the same or in one tet), at `positions`
 *  (num_vertices x 3, read in place), with the detector's topology, object options and threads. Writes their number
 *  to `out_count` (may be NULL); they stay readable until the next call or set_topology. Independent of
 *  tethash_detector_detect (its contacts are kept). */
tethash_status tethash_detector_find_edge_contacts(tethash_detector* detector, const double* positions,
                                                   int64_t num_vertices, int64_t* out_count);
/** Copies the edge-face contacts of the last tethash_detector_find_edge_contacts, sorted by (edge, face), into caller
 *  arrays of `capacity` rows, each may be NULL: edge (capacity x 2 vertex ids, increasing), face (capacity x 3 vertex
 *  ids, outward order), objects (capacity x 2: the edge's, the face's), t (capacity: the crossing point is
 *  (1 - t) x[edge0] + t x[edge1]), face_bary (capacity x 3), inner_end (capacity: 0 or 1, the end of the edge on the
 *  triangle's inner side), normal (capacity x 3: the triangle's unit normal from its inner to its outer side).
 *  `capacity` must be at least their count. */
tethash_status tethash_detector_get_edge_contacts(const tethash_detector* detector, int64_t capacity, int32_t* edge,
                                                  int32_t* face, int32_t* objects, double* t, double* face_bary,
                                                  int32_t* inner_end, double* normal);

/** Continuous queries (ccd.hpp): whether two primitives moving linearly from their start positions (t = 0) to their
 *  end positions (t = 1) meet. `start` and `end`: 4 x 3 doubles each, vertex-face (p, a, b, c: the vertex and the
 *  triangle's corners) or edge-edge (ea0, ea1, eb0, eb1). `tolerance` > 0 (in the coordinates' units; 1e-6 for
 *  unit-sized scenes) and `max_iterations` >= 1 (1000000) as in CcdParams. *out_hit: 1 when they may meet, never 0
 *  when they do; *out_toi: when hit, a time in [0, 1] no later than the first contact, else 1. */
tethash_status tethash_ccd_vertex_face(const double* start, const double* end, double tolerance, int64_t max_iterations,
                                       int32_t* out_hit, double* out_toi);
tethash_status tethash_ccd_edge_edge(const double* start, const double* end, double tolerance, int64_t max_iterations,
                                     int32_t* out_hit, double* out_toi);

/** Continuous detection over a step (continuous.hpp): every boundary vertex against every boundary face and every
 *  boundary edge against every boundary edge of the detector's topology, moving linearly from `start` (t = 0) to
 *  `end` (t = 1), each num_vertices x 3 and read in place; pairs that share a vertex are left out, every other pair
 *  is tested, within an object and between objects (the object options do not apply: the contacts carry vertex ids,
 *  the caller keeps what its rules allow). `tolerance` and `max_iterations` as in tethash_ccd_vertex_face; the
 *  detector's threads. Nothing that meets within the step is missed. Writes the number of contacts to `out_count`
 *  (may be NULL); they stay readable until the next call or set_topology. Independent of tethash_detector_detect. */
tethash_status tethash_detector_detect_continuous(tethash_detector* detector, const double* start, const double* end,
                                                  int64_t num_vertices, double tolerance, int64_t max_iterations,
                                                  int64_t* out_count);
/** Copies the contacts of the last tethash_detector_detect_continuous, vertex-face first, each sorted, into caller
 *  arrays of `capacity` rows, each may be NULL: kind (capacity: 0 vertex-face, 1 edge-edge), vertices (capacity x 4
 *  vertex ids: the vertex then the face's corners in outward order, or the first edge's two ends then the second's),
 *  toi (capacity: a time in [0, 1] no later than the pair's first contact). `capacity` must be at least their
 *  count. */
tethash_status tethash_detector_get_continuous_contacts(const tethash_detector* detector, int64_t capacity,
                                                        int32_t* kind, int32_t* vertices, double* toi);
/** A locality rule for tethash_detector_detect_continuous (ContinuousDetector::set_locality in continuous.hpp),
 *  applied in its broad phase: a pair is left out when the first vertices of its two primitives are of one group g
 *  and some vertex of one and some vertex of the other lie nearer than the group's reach in `rest`: squared distance
 *  below reach_sq[g] (parts that a simulator's elastic terms keep apart: neighbours on the surface). `rest`:
 *  num_vertices x 3 (num_vertices as in set_topology); `vertex_group`: num_vertices entries in [0, num_groups);
 *  `reach_sq`: num_groups entries >= 0 (0: no pair of that group is local); all copied. num_groups = 0 removes the
 *  rule (vertex_group and reach_sq may then be NULL). Kept until the next set_topology (object options keep it); a
 *  refused rule leaves the one before. Drops the last continuous contacts. */
tethash_status tethash_detector_set_continuous_locality(tethash_detector* detector, const double* rest,
                                                        int64_t num_vertices, const int32_t* vertex_group,
                                                        const double* reach_sq, int64_t num_groups);
/** The broad phase's work in the last tethash_detector_detect_continuous (ContinuousResult::broad_phase_pairs): the
 *  pairs its grid met whose boxes passed its single-precision test, before the exact box test, the shared-vertex and
 *  locality rules, each pair once (0 before any call). */
tethash_status tethash_detector_continuous_broad_phase_pairs(const tethash_detector* detector, int64_t* out_pairs);

#ifdef __cplusplus
} /* extern "C" */
#endif

#endif /* TETHASH_TETHASH_H */
