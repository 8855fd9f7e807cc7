#pragma once
/// \file study/scenarios.hpp
/// The five test scenarios of Teschner et al. 2003 ("Optimized Spatial Hashing for Collision Detection of
/// Deformable Objects", table 1), rebuilt with tethash's own generator (meshing::generate): the same numbers of
/// objects, tets and vertices (approximately: the generator's lattice decides the exact counts), objects
/// packed so that neighbours overlap heavily and the detector finds real contacts. Deterministic.
/// Used by `tethash study --teschner-scenarios` and by the benchmark.

#include "tethash/mesh.hpp"

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

} // namespace tethash::study
