#pragma once
// The FEM code's contact module: tethash finds the nodes inside other tets (on the FEM's own position array, no
// copy) and estimates how deep they are and which way out (Penetration); each such node gets a penalty
// E = ½ k d², its force and its (Gauss-Newton) stiffness go into the Newton system.

#include "fem.hpp"

#include <tethash/detect.hpp>
#include <tethash/penetration.hpp>

#include <unordered_map>

namespace fem {

struct ContactSettings {
    double stiffness = 1e6; ///< penalty k [N/m]
    double skin = 0.2;      ///< candidate reuse between Newton iterations: a factor of the cell size (0: off)
    int threads = 0;        ///< detector threads (0: all)
};

/// What the last call found.
struct ContactReport {
    int contacts = 0;                    ///< (node, penetrated object) pairs given a penalty
    int self_contacts = 0;               ///< of those, within one object
    double max_depth = 0;                ///< largest estimated depth
    double energy = 0;                   ///< Σ ½ k d²
    double ms_tethash = 0;               ///< wall time in Detector::detect + Penetration::compute
    bool reused = false;                 ///< the detector reused its kept candidates (skin)
    std::vector<double> force;           ///< contact force on each object (3 per object)
    std::vector<tethash::Contact> pairs; ///< the contacts used, with depth and direction
    double stiffness = 0;                ///< the penalty k used
};

class ContactModule {
  public:
    /// Topology once: tets, node and tet objects (every object may touch itself).
    ContactModule(const Mesh& mesh, const ContactSettings& settings);
    /// At positions x (the FEM's 3n array, read in place as n × 3): adds penalty forces to f and their stiffness
    /// to K (if given), fills `report`.
    void add(const Vec& x, Vec& f, Triplets* K, ContactReport& report);
    /// Exact distance of each contact of the report to the penetrated object's surface (for checks).
    std::vector<double> exact_depths(const Vec& x, const ContactReport& report) const;
    /// A new time step: penalty directions are taken afresh from the next evaluation.
    void begin_step() { m_directions.clear(); }

  private:
    tethash::Detector m_detector;
    tethash::Penetration m_penetration;
    ContactSettings m_settings;
    std::vector<std::int32_t> m_tets;
    std::unordered_map<std::int64_t, Eigen::Vector3d> m_directions; ///< (node, object) → direction this step
    int m_nodes = 0, m_objects = 0;
};

} // namespace fem
