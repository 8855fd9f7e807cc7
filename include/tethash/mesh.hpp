#pragma once
/// \file mesh.hpp
/// TetMesh: one or several tetrahedral objects in one set of arrays, plus validation and
/// derived data (edges, boundary, adjacency, statistics, quality), computed on request only.
///
/// Layout: positions are an n × 3 row-major double array, tets an m × 4 row-major int32 array,
/// so that an FEM code's own `std::vector<double>` of xyz triples maps onto them without a copy
/// (see `PositionsRef` / `TetsRef` and `Eigen::Map`).

#include "tethash/error.hpp"

#include <Eigen/Core>

#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace tethash {

using Index = std::int32_t;
using Positions = Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>; ///< n × 3
using Tets = Eigen::Matrix<Index, Eigen::Dynamic, 4, Eigen::RowMajor>;       ///< m × 4
using Triangles = Eigen::Matrix<Index, Eigen::Dynamic, 3, Eigen::RowMajor>;  ///< k × 3
using Edges = Eigen::Matrix<Index, Eigen::Dynamic, 2, Eigen::RowMajor>;      ///< e × 2
using PositionsRef = Eigen::Ref<const Positions>;
using TetsRef = Eigen::Ref<const Tets>;

/// One or several tetrahedral objects.
struct TetMesh {
    Positions positions;              ///< n × 3, current positions
    Positions rest_positions;         ///< n × 3, rest state; empty means "same as positions"
    Tets tets;                        ///< m × 4 vertex indices, 0-based
    std::vector<Index> vertex_object; ///< n object ids (empty: all 0)
    std::vector<Index> tet_object;    ///< m object ids (empty: all 0)
    std::vector<Index>
        tet_label; ///< m labels from the file (Gmsh physical tag, Medit ref, TetGen attribute); empty if none
    std::vector<Index> vertex_label; ///< n labels from the file (Medit ref, TetGen marker); empty if none

    Index num_vertices() const { return static_cast<Index>(positions.rows()); }
    Index num_tets() const { return static_cast<Index>(tets.rows()); }
    /// Number of objects: 1 + the largest object id (1 for a mesh without object ids, 0 if empty).
    Index num_objects() const;
    /// Rest positions, or positions if no rest state was set.
    const Positions& rest() const { return rest_positions.rows() ? rest_positions : positions; }
    /// Fills vertex_object/tet_object with zeros where they are empty.
    void ensure_object_ids();
    /// Appends `other` as new object(s): indices shifted, object ids offset by num_objects().
    void append(const TetMesh& other);
    /// Checks array shapes and index ranges only (cheap); throws Error naming `what` and the first offending element.
    void check_consistency(const std::string& what = "mesh") const;
};

/// Signed volume (b-a)·((c-a)×(d-a))/6 of tet t; positive for the positive orientation.
double signed_volume(const PositionsRef& positions, const std::array<Index, 4>& tet);

/// What validation found. Counts plus the first few offending ids of each kind.
struct ValidationReport {
    std::int64_t index_out_of_range = 0; ///< tets with an index < 0 or ≥ n
    std::int64_t repeated_index = 0;     ///< tets with a vertex twice
    std::int64_t non_finite = 0;         ///< vertices with NaN/Inf coordinates
    std::int64_t degenerate_tets = 0;    ///< |volume| ≤ eps · (mean edge)^3 (zero volume)
    std::int64_t inverted_tets = 0;      ///< volume < 0 and not degenerate
    std::int64_t unreferenced_vertices = 0;
    std::int64_t non_manifold_faces = 0;       ///< faces shared by more than two tets
    std::vector<Index> first_bad_tets;         ///< up to 10 tet ids with any problem
    std::vector<Index> first_bad_vertices;     ///< up to 10 vertex ids with any problem
    bool ok() const;                           ///< no fatal problem (range, repeat, non-finite)
    std::vector<std::string> problems() const; ///< human-readable lines, one per kind found
};

/// Full validation; never throws on bad content (only reports).
ValidationReport validate(const TetMesh& mesh);
/// Swaps two vertices of every inverted (negative-volume, non-degenerate) tet; returns how many.
std::int64_t reorient_inverted(TetMesh& mesh);

/// What to do with a vertex used by tets of different labels in split_objects_by_label.
enum class SharedLabelVertices {
    error, ///< throw Error naming the vertex and the two labels (default: the file is not separate bodies)
    join,  ///< labels that share a vertex become one object (glued regions are one body)
};

/// Result of split_objects_by_label.
struct LabelSplit {
    /// For each object, the labels it holds (sorted; more than one only where SharedLabelVertices::join merged).
    std::vector<std::vector<Index>> object_labels;
    /// Vertices used by tets of more than one label (0 unless join merged something).
    std::int64_t shared_vertices = 0;
};

/// Makes each tet label (Gmsh physical tag, else entity tag; Medit ref; TetGen region attribute) an
/// object: object ids 0, 1, ... in increasing label order, set in tet_object and vertex_object; a
/// vertex takes the object of its tets; a vertex of no tet goes to the object of the smallest label
/// (object 0). tet_label itself is kept. A mesh without labels (tet_label empty) is one object, 0.
/// Throws Error (naming `what`, the vertex and both labels) for a vertex shared by tets of different
/// labels when `shared` is SharedLabelVertices::error.
LabelSplit split_objects_by_label(TetMesh& mesh, SharedLabelVertices shared = SharedLabelVertices::error,
                                  const std::string& what = "mesh");

// ---- derived data: each computed when called, nothing cached in the mesh -------------

/// Unique undirected edges (i < j), sorted lexicographically.
Edges unique_edges(const TetsRef& tets);
/// Boundary faces (used by exactly one tet), oriented outward for positively oriented tets.
Triangles boundary_faces(const TetsRef& tets);
/// Compressed vertex → vertex adjacency (through tet edges): offsets (n+1) and sorted neighbours.
struct Adjacency {
    std::vector<Index> offsets;
    std::vector<Index> neighbours;
};
Adjacency vertex_adjacency(const TetsRef& tets, Index num_vertices);
/// Compressed vertex → tets incidence.
Adjacency vertex_tets(const TetsRef& tets, Index num_vertices);

struct EdgeStats {
    double min = 0, mean = 0, max = 0;
    std::int64_t count = 0;
};
EdgeStats edge_stats(const PositionsRef& positions, const TetsRef& tets);

struct VolumeStats {
    double min = 0, mean = 0, max = 0, total = 0;
};
VolumeStats volume_stats(const PositionsRef& positions, const TetsRef& tets);

/// Per-tet quality: dihedral angles in degrees and aspect ratio (longest edge / (2·sqrt(6)·inradius), 1 for regular).
struct TetQuality {
    double min_dihedral_deg = 0, max_dihedral_deg = 0, aspect_ratio = 0;
};
TetQuality tet_quality(const PositionsRef& positions, const std::array<Index, 4>& tet);

/// Connected components of the tets, tets that share a vertex being connected. Returns the number of
/// components; `component`, when given, gets the component of each tet (0, 1, ... in the order of their first tet).
Index tet_components(const TetsRef& tets, Index num_vertices, std::vector<Index>* component = nullptr);

/// Bounding box of the positions (min, max); both zero for an empty set.
std::pair<Eigen::Vector3d, Eigen::Vector3d> bounding_box(const PositionsRef& positions);

} // namespace tethash
