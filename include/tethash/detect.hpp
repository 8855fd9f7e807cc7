#pragma once
/// \file detect.hpp
/// The three-stage spatial-hash collision detection of Teschner et al. 2003 for deformable
/// tetrahedral meshes: (1) hash every vertex into an infinite uniform grid through a hash table,
/// (2) hash the cells touched by every tet's bounding box into the same table, (3) test each vertex
/// found there against the tet (closed inside test, exact).
///
/// Usage from an FEM code (no copies of its arrays):
/// \code
///   tethash::Detector det;                       // parameters: defaults (auto cell and table size)
///   det.set_topology(tets);                      // once: m × 4 int32 row-major, validated here
///   for (each step) {
///       const auto& contacts = det.detect(positions);   // n × 3 double row-major
///       for (const tethash::Contact& c : contacts) ...
///   }
/// \endcode

#include "tethash/error.hpp"
#include "tethash/mesh.hpp"

#include <cstdint>
#include <limits>
#include <memory>
#include <span>
#include <vector>

namespace tethash {

struct CellLayout; // portals.hpp

/// A vertex lying inside (or on the boundary of) a tet it does not belong to.
/// Plain data, 80 bytes; arrays of it are sorted by (vertex, tet).
struct Contact {
    Index vertex = -1;             ///< global vertex id
    Index tet = -1;                ///< global tet id
    Index vertex_object = 0;       ///< object of the vertex
    Index tet_object = 0;          ///< object of the tet
    double bary[4] = {0, 0, 0, 0}; ///< barycentric coordinates of the vertex in the tet (sum 1, all ≥ 0 up to rounding)
    /// Penetration depth (length units, ≥ 0) and unit direction pointing out of the penetrated object;
    /// NaN unless penetration was requested (see penetration.hpp).
    double depth = std::numeric_limits<double>::quiet_NaN();
    double direction[3] = {0, 0, 0};
};

/// Hash function of the infinite grid's cells onto the table.
enum class HashFunction {
    teschner, ///< (x·73856093 xor y·19349663 xor z·83492791) mod n  (the 2003 paper)
    column,   ///< mix(x, y) + z: cells of one z-run land in consecutive buckets (one lookup per column)
};
/// "teschner" / "column" (parse_hash_function in detect_grammar.hpp reads them).
const char* to_string(HashFunction h);

/// The broad phase that hands candidate (vertex, tet) pairs to the exact inside test. Every method returns the same
/// contacts (the oracle's); they differ in time, memory and the candidates they hand on (docs/partitions.md).
enum class Method {
    hash,              ///< the spatial hash of Teschner et al. 2003 (the default; the only one with candidate reuse)
    brute_force,       ///< every vertex against every tet box (vertices sorted by x: each tet looks at its x-extent)
    uniform_grid,      ///< a dense array of cells over the scene's bounding box (the storage the hash replaces)
    hierarchical_grid, ///< hashed grids of doubling cell size, each tet on the level its size fits (Mirtich 1998)
    octree,            ///< region octree over the vertices: split at the cell centre
    octree_point,      ///< point octree: split at the median of the contents
    octree_loose,      ///< loose octree over the tets: cells enlarged by `looseness`, each tet in one cell
    kd_tree,           ///< region k-d tree: mid-plane, axis cycling
    kd_tree_point,     ///< point k-d tree: median plane, axis cycling
    bsp_tree,          ///< BSP tree with the comparison paper's rule (median point, normal turned 90° about x, y, z)
    bsp_tree_balanced, ///< BSP tree choosing among candidate planes the most even split
    sort_sweep,        ///< sort and sweep on the axis of largest variance, insertion sort from the last order
    bvh,               ///< bounding-volume hierarchy over the tet boxes, rebuilt every call
    bvh_refit,         ///< the same hierarchy, built once and refitted (rebuilt when refitting has degraded it)
    portals,           ///< cells and portals (portals.hpp): boxes by the cell of their centre, tracked by segment tests
    automatic,         ///< the method that measured fastest for the scene's kind (docs/results.md)
};
/// The names of the text grammar ("hash", "brute", "grid", "hgrid", ..., "auto"; parse_method in detect_grammar.hpp
/// reads them).
const char* to_string(Method m);
/// Every method but `automatic`, in the order above.
std::span<const Method> all_methods();

/// Parameters of the methods other than the hash. 0 = the method's default.
struct PartitionParams {
    int max_depth = 0;    ///< trees: deepest level (0: the method's default; at most 30)
    int leaf_size = 0;    ///< trees: items a node holds before it splits; portals: vertices per slab (0: the default)
    double looseness = 0; ///< loose octree: cell enlargement factor ≥ 1 (0: 2)
    int levels = 0;       ///< hierarchical grid: most levels (0: as many as the tet sizes span, at most 32)
    /// portals: the cells and portals (checked by set_params); null: a grid of cells of the method's own making over
    /// the vertices' box, every shared face a portal.
    std::shared_ptr<const CellLayout> cells;
};

/// Per-object options. Objects not listed get the defaults.
struct ObjectOptions {
    bool self_collision = true; ///< report contacts between a vertex and a tet of the same object
    bool is_static = false;     ///< positions never change: hashed once; static-static pairs are never reported
};

struct DetectParams {
    /// Grid cell edge length l. ≤ 0 is invalid when `cell_size_mode == absolute`.
    enum class CellSizeMode { auto_mean_edge, absolute, factor_of_mean_edge };
    CellSizeMode cell_size_mode = CellSizeMode::auto_mean_edge;
    double cell_size = 1.0;      ///< absolute length, or the factor for factor_of_mean_edge
    std::int64_t table_size = 0; ///< number of buckets; 0 = automatic from the vertex count
    HashFunction hash = HashFunction::column;
    int threads = 0; ///< 0 = OpenMP default; 1 = serial
    /// Candidate reuse between calls (moving scenes, as the neighbour lists of molecular dynamics). With a skin
    /// s > 0 a full detection collects each tet's candidates with its box inflated by s and keeps them; a later
    /// call whose moving vertices all moved less than s/2 per axis since that detection, once their common
    /// translation is taken off (static vertices count as not moving), only re-runs the exact inside tests on the
    /// kept candidates (same contacts, bit for bit). 0 = off (the default). Must be ≥ 0 and
    /// finite. Costs 24 bytes per vertex plus 4 bytes per kept candidate (see docs/detection.md). When a kept list
    /// was not reused even once (the scene deforms faster than s/2 per call), full detections run without the skin
    /// until a call moved less than s/4 since the previous one (DetectStats::skin then reads 0).
    enum class SkinMode { absolute, factor_of_cell_size };
    SkinMode skin_mode = SkinMode::absolute;
    double skin = 0; ///< a length, or the factor of the cell size for factor_of_cell_size
    /// The broad phase. Methods other than `hash` ignore `table_size`, `hash` and the skin; the grids use the cell
    /// size (the hierarchical grid as its finest level).
    Method method = Method::hash;
    PartitionParams partition{};
};

/// Statistics of one detect() call. Times in milliseconds: ms_total is the whole call; ms_setup the one-off set-up
/// of the first call after set_topology()/set_params() (automatic cell size, the static vertices' table; 0 on later
/// calls); the stages (ms_vertices … ms_sort, each the slowest thread's) follow it.
struct DetectStats {
    double ms_total = 0, ms_setup = 0, ms_vertices = 0, ms_tets = 0, ms_inside = 0, ms_sort = 0;
    double cell_size = 0;        ///< l actually used
    std::int64_t table_size = 0; ///< n actually used
    int threads = 1;
    std::int64_t vertices = 0, tets = 0;
    std::int64_t cells_visited = 0;    ///< grid cells enumerated from tet boxes
    std::int64_t entries_scanned = 0;  ///< bucket entries looked at
    std::int64_t hash_collisions = 0;  ///< scanned entries whose cell differs from the visited cell
    std::int64_t box_rejections = 0;   ///< candidates rejected by the tet's bounding box
    std::int64_t own_vertex_skips = 0; ///< candidates that were one of the tet's own vertices
    std::int64_t inside_tests = 0;     ///< barycentric / orientation tests made
    std::int64_t exact_fallbacks = 0;  ///< tests the floating-point filter could not decide
    std::int64_t degenerate_tets = 0;  ///< zero-volume tets skipped
    std::int64_t contacts = 0;
    double table_load = 0;              ///< vertices / table size
    std::int64_t memory_bytes = 0;      ///< detector working memory
    double skin = 0;                    ///< skin actually used (length; 0 = no candidate reuse, or paused)
    int reused = 0;                     ///< 1: stages 1-2 skipped, the kept candidates were tested (skin > 0)
    std::int64_t cached_candidates = 0; ///< candidates kept for reuse (skin > 0; 0 otherwise)
    /// Candidate pairs handed to the exact stage: the vertices in a tet's box that are not its own (for the hash:
    /// the vertices its scan kept).
    std::int64_t candidates = 0;
    std::int64_t nodes = 0; ///< other methods: cells, nodes or levels of the structure (0 for the hash)
    /// portals: segment tests of points (vertices, tet box centres) that left their cell since the last call, and
    /// tet boxes entered in a cell besides the one holding their centre (they overlap a portal or a wall).
    std::int64_t ray_tests = 0, portal_overlaps = 0;
};

class DetectorImpl;

/// Owns every buffer and reuses it across calls; after the first call on a scene, detect() does not allocate.
/// Not thread-safe itself (one detect() at a time per Detector); parallel inside.
class Detector {
  public:
    Detector();
    explicit Detector(const DetectParams& params);
    ~Detector();
    Detector(Detector&&) noexcept;
    Detector& operator=(Detector&&) noexcept;
    Detector(const Detector&) = delete;
    Detector& operator=(const Detector&) = delete;

    /// Sets parameters; validated (throws Error naming the parameter and value).
    void set_params(const DetectParams& params);
    const DetectParams& params() const;
    /// Changes the thread count alone (0 = every hardware thread), keeping the set-up and the kept candidates (a
    /// call with another count than the last runs a full detection): for a caller that adapts its count between
    /// calls. The contacts do not depend on it. Throws Error outside 0..max(256, hardware threads).
    void set_threads(int threads);

    /// Sets the topology once. `tets` is m × 4; `vertex_object`/`tet_object` give object ids (empty: all 0);
    /// `objects[k]` gives the options of object k (missing: defaults). The number of vertices is fixed here.
    /// Throws Error on indices out of range or object ids out of range. A tet with a repeated vertex (collapsed,
    /// zero volume) is accepted and skipped like every degenerate tet (DetectStats::degenerate_tets).
    void set_topology(const TetsRef& tets, Index num_vertices, std::span<const Index> vertex_object = {},
                      std::span<const Index> tet_object = {}, std::span<const ObjectOptions> objects = {});
    /// Convenience: topology and object ids of a TetMesh.
    void set_topology(const TetMesh& mesh, std::span<const ObjectOptions> objects = {});

    /// Runs the three stages on `positions` (n × 3, n as in set_topology). Throws Error on a non-finite
    /// position or a wrong row count. Returns the contacts sorted by (vertex, tet), valid until the next call.
    const std::vector<Contact>& detect(const PositionsRef& positions, DetectStats* stats = nullptr);

    /// The contacts of the last detect() call (mutable so that penetration can fill depth and direction).
    std::vector<Contact>& contacts();

  private:
    std::unique_ptr<DetectorImpl> m_impl;
};

/// Mean edge length of the unique edges of `tets` at `positions` (the default cell size).
double mean_edge_length(const PositionsRef& positions, const TetsRef& tets);

} // namespace tethash
