#pragma once
/// \file study/scenarios.hpp
/// The five test scenarios of Teschner et al. 2003 ("Optimized Spatial Hashing for Collision Detection of
/// Deformable Objects", table 1), rebuilt with tethash's own generator (meshing::generate): the same numbers of
/// objects, tets and vertices (approximately: the generator's lattice decides the exact counts), objects
/// packed so that neighbours overlap heavily and the detector finds real contacts. Deterministic.
/// Used by `tethash study --teschner-scenarios` and by the benchmark.

#include "tethash/error.hpp"
#include "tethash/mesh.hpp"
#include "tethash/portals.hpp"

#include <Eigen/Core>

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace tethash::study {

/// What the paper lists for one scenario.
struct ScenarioSpec {
    std::string name;    ///< "teschner1" .. "teschner5"
    int objects = 0;     ///< number of objects
    int tets = 0;        ///< total tets in the paper
    int vertices = 0;    ///< total vertices in the paper
    double paper_ms = 0; ///< the paper's detection time (Pentium 4, 1.8 GHz), milliseconds
};

/// The five scenarios of the paper's table: (100, 1000, 1200), (8, 4000, 1936), (20, 10000, 4840),
/// (2, 20514, 5898), (100, 50000, 24200) with 6, 15, 34, 72, 174 ms.
const std::vector<ScenarioSpec>& teschner_specs();

/// A rebuilt scenario: every object is a copy of one generated shape, rotated and placed in a packed cluster
/// (centre spacing 0.6 × the object's size) so that each object overlaps its neighbours.
struct Scenario {
    ScenarioSpec spec;
    TetMesh mesh;       ///< all objects; vertex_object / tet_object set (0 .. objects-1)
    std::string shape;  ///< generator shape of each object
    int resolution = 0; ///< generator resolution of each object
};

/// Scenario `index` (0 .. 4). Throws Error for an index out of range.
Scenario teschner_scenario(int index);
/// All five.
std::vector<Scenario> teschner_scenarios();

/// Scenes of the space-partition comparison (`tethash study method --partition-scenes`, tethash_bench): where the
/// spatial hash is at its worst, and many small objects each touching several. Objects are cut from cube lattices
/// at six tets per cube (Kuhn's subdivision, positively oriented). Deterministic.
///  - "bars": 100 bars of 1 × 2 × 42 cubes (50,400 tets, 25,800 vertices, V/T 0.51) in random directions, their
///    centres in a box 30 long so that every bar crosses several others: unlike scenario 5, long thin objects.
///  - "sizes": tet sizes spanning three decades: a 4³-cube object of edge 1 and, overlapping it, 3 of edge 0.1, 10
///    of edge 0.01 and 60 of edge 0.001 (the mean edge, the hash's cell, is far below the big tets and far above
///    the small ones).
///  - "corner": 60 overlapping 4³-cube objects clustered in a corner (0.7 wide) of a domain 16 wide, whose far
///    corner holds one more small object (the scene's box is mostly empty).
///  - "thin": 12 objects of 2 × 20 × 20 cubes of 1 × 0.1 × 0.1 (tets ten times longer than wide), randomly rotated
///    and packed so that neighbours overlap.
///  - "building": building_scene(4, 4): 16 rooms joined by 24 doors, 208 small objects (pairs overlapping) spread
///    over the rooms and standing in every doorway, with its cells and portals.
///  - "walled": the building's objects with cells made from its walls (cells_from_obstacles on building_walls(4, 4):
///    free boxes between the walls joined by portals through the doors), not from its rooms.
///  - "hall": the building's objects in one open hall: one cell, no portal (where cells and portals cannot help).
struct NamedScene {
    std::string name;
    std::string description;
    TetMesh mesh; ///< vertex_object / tet_object set
    /// The cells and portals of the scene (the building's rooms and doors), for Method::portals; null for the
    /// scenes without (the method then makes its own).
    std::shared_ptr<const CellLayout> cells;
    /// The building's walls as static obstacles (building_walls), for the object-world part; null for the others.
    std::shared_ptr<const ObstacleSet> walls;
};
/// The names above, in that order.
const std::vector<std::string>& partition_scene_names();
/// The scene `name`; throws Error naming the list for an unknown name.
NamedScene partition_scene(const std::string& name);
/// A building of nx × ny rooms of 4 × 4 × 3 on one floor (room (i, j) spans x 4i..4i+4, y 4j..4j+4, z 0..3), each
/// joined to its neighbours by a door 1 wide and 2 high in the middle of their shared wall. In every room 5 pairs of
/// overlapping objects at random places, in every doorway one such pair straddling the door; each object a
/// 3 × 3 × 3-cube lattice of edge 0.1 (162 tets, 64 vertices), randomly rotated. Deterministic in `seed`. The
/// cells and portals are the rooms and doors (room names "rI_J").
NamedScene building_scene(int nx, int ny, std::uint64_t seed = 0x5ca1ab1eULL);
/// The walls of building_scene(nx, ny) as box obstacles 0.1 thick, centred on the rooms' borders, 3 high: the outer
/// walls whole, the inner ones with the gaps of the doors (1 wide, 2 high, a lintel above each).
ObstacleSet building_walls(int nx, int ny);
/// An nx × ny × nz lattice of boxes of size h (corner at the origin), six tets per box: one object.
TetMesh cube_lattice(int nx, int ny, int nz, const Eigen::Vector3d& h);

} // namespace tethash::study
