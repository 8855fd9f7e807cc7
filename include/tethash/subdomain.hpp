#pragma once
/// \file subdomain.hpp
/// Detection on subdomains (the ranks of a domain-decomposed code): each subdomain detects on its local mesh
/// (what it owns plus a ghost layer) and reports only the contacts it owns, so that every contact is reported
/// exactly once and the union over subdomains equals the detection on the whole mesh. Nothing here communicates:
/// a code gathers the ghost layer with its own MPI calls (examples/mpi_detect) and hands the local arrays and the
/// ownership masks to these functions.
///
/// The rules (docs/embedding.md, "MPI"):
/// - Ownership of a contact (vertex v inside tet t): ContactOwner::tet, the subdomain owning t reports it (a
///   pair that straddles two subdomains belongs to the tet's side); or ContactOwner::vertex, the owner of v.
/// - Ghost width w = max_tet_extent + skin. A vertex inside a tet lies in the tet's bounding box, whose sides are
///   at most max_tet_extent long and which holds the tet's centroid; so with tets owned by the region holding
///   their centroid (and vertices by the region holding them), every vertex a subdomain's owned tet can contain
///   lies within max_tet_extent of the region (per axis), and every tet that can contain an owned vertex has its
///   centroid there. The skin adds what positions may move (each vertex less than skin / 2) before the ghost
///   layer must be gathered again.
///
/// \code
///   // once per repartition: regions, owners, the local mesh of this rank
///   auto regions = tethash::bisect_regions(centroids, ranks);
///   tethash::Subdomain sub = tethash::make_subdomain(positions, tets, vertex_part, tet_part, rank,
///                                                    regions[rank], tethash::ghost_width(positions, tets, skin));
///   det.set_topology(sub.local_tets, sub.vertices.size());
///   // every step: local positions (owned + ghost), then
///   tethash::detect_owned(det, local_positions, sub, tethash::ContactOwner::tet, contacts);
/// \endcode

#include "tethash/detect.hpp"
#include "tethash/error.hpp"
#include "tethash/mesh.hpp"

#include <Eigen/Core>

#include <cstdint>
#include <span>
#include <vector>

namespace tethash {

/// Who reports a contact whose vertex and tet belong to different subdomains.
enum class ContactOwner {
    tet,    ///< the subdomain owning the tet (the default)
    vertex, ///< the subdomain owning the vertex
};

/// Longest side of any tet's axis-aligned bounding box (0 without tets).
double max_tet_extent(const PositionsRef& positions, const TetsRef& tets);
/// The ghost width of the subdomains: max_tet_extent(positions, tets) + skin (skin ≥ 0, a length).
double ghost_width(const PositionsRef& positions, const TetsRef& tets, double skin = 0);

/// A region of space, lo ≤ x < hi per axis (outer sides are ±infinity).
struct Region {
    Eigen::Vector3d lo, hi;
    bool contains(const Eigen::Vector3d& p) const;
    /// Largest per-axis distance from p to the region (0 inside).
    double distance(const Eigen::Vector3d& p) const;
};

/// Recursive coordinate bisection of `points` (n × 3) into `parts` regions that tile space: each step cuts the
/// current points' box across its longest axis at the point that splits them in proportion to the parts on
/// either side. Regions are numbered in the order of the recursion (left before right). parts ≥ 1.
std::vector<Region> bisect_regions(const PositionsRef& points, int parts);
/// The region holding p (regions tile space, so exactly one does).
int region_of(const std::vector<Region>& regions, const Eigen::Vector3d& p);
/// Tet centroids (m × 3), what the tets are partitioned by.
Positions tet_centroids(const PositionsRef& positions, const TetsRef& tets);

/// A subdomain's local mesh: global ids of its vertices and tets (ascending), which of them it owns, and its tets
/// in local vertex numbering.
struct Subdomain {
    std::vector<Index> vertices;                  ///< global ids of the local vertices, ascending
    std::vector<Index> tets;                      ///< global ids of the local tets, ascending
    std::vector<std::uint8_t> vertex_owned;       ///< per local vertex: 1 owned, 0 ghost
    std::vector<std::uint8_t> tet_owned;          ///< per local tet: 1 owned, 0 ghost
    Tets local_tets;                              ///< local tets, local vertex ids
    std::vector<Index> vertex_object, tet_object; ///< object ids of the local vertices and tets (empty: all 0)
    /// The local positions (|vertices| × 3) gathered from a global array.
    Positions gather(const PositionsRef& global_positions) const;
};

/// The local mesh of subdomain `part` from the whole mesh (what a code that holds the whole mesh on each
/// process, or a test, does; an MPI code builds the same from its neighbours' messages): owned tets and vertices
/// are those whose `tet_part` / `vertex_part` is `part`. ContactOwner::tet: local tets are the owned ones, local
/// vertices the owned ones, the corners of owned tets and every vertex within `width` of `region`.
/// ContactOwner::vertex: local tets are the owned ones and every tet whose centroid lies within `width` of
/// `region` (ghost tets), local vertices the owned ones and the corners of local tets. Object ids are carried
/// over from `vertex_object` / `tet_object` when given.
Subdomain make_subdomain(const PositionsRef& positions, const TetsRef& tets, std::span<const int> vertex_part,
                         std::span<const int> tet_part, int part, const Region& region, double width,
                         ContactOwner owner = ContactOwner::tet, std::span<const Index> vertex_object = {},
                         std::span<const Index> tet_object = {});

/// Of `local` (contacts of a detection on a subdomain's local mesh, local ids), the ones the subdomain reports
/// under `owner` (tet_owned / vertex_owned: per local tet / vertex, 1 owned), renumbered with the global ids
/// `tet_global` / `vertex_global` (per local tet / vertex), sorted by (vertex, tet). Throws Error on masks or
/// maps whose size differs from the local mesh's (the largest local id in `local` decides).
void owned_contacts(std::span<const Contact> local, std::span<const std::uint8_t> vertex_owned,
                    std::span<const std::uint8_t> tet_owned, std::span<const Index> vertex_global,
                    std::span<const Index> tet_global, ContactOwner owner, std::vector<Contact>& out);

/// Detects on the local positions (the detector's topology is sub.local_tets) and keeps the owned contacts in
/// `out` (global ids, sorted). Returns `out`.
const std::vector<Contact>& detect_owned(Detector& detector, const PositionsRef& local_positions, const Subdomain& sub,
                                         ContactOwner owner, std::vector<Contact>& out, DetectStats* stats = nullptr);

} // namespace tethash
