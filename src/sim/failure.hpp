#pragma once
// Blow-up checks (private to tethash::sim): a cheap O(n) test after every substep and an energy test after every
// step, with the likely cause named in the message.

#include "contact_response.hpp"

#include "tethash/sim/model.hpp"
#include "tethash/sim/scene.hpp"

#include <string>
#include <vector>

namespace tethash::sim {

class FailureCheck {
  public:
    /// Reference energy: all the energy the scene can draw on at start (initial energy plus the gravity drop over
    /// the scene's height), and the speed no vertex can reach on it.
    void setup(const Model& model, const Positions& x, const Positions& v, double contact_energy);

    /// Empty when the state after a substep ending at time t_end is sane; else what is wrong: a non-finite
    /// vertex, a vertex farther from the scene than the energy at start can carry it, an exploded kinetic energy.
    std::string check_substep(const Model& model, const Positions& x, const Positions& v, double t_end) const;
    /// Empty when the internal energy after a step is below 1000 × the reference; else what is wrong.
    std::string check_energy(double internal) const;
    /// Called after every step ending at time t with the inverted tets then (find_inverted_tets). Empty unless the
    /// body crumpled: more than 1 % of the dynamic tets inverted (signed volume ≤ 0; rest volumes are positive) for 0.1
    /// s of simulated time without a break, or more than 10 % at once (an impact inverts a few tets for a few steps;
    /// they recover). Else how many, and the likely cause: a material too soft to carry its own weight, a much denser
    /// body crushing a lighter one, or a time step too large for the material.
    std::string check_inverted(const Model& model, const Scene& scene, std::int64_t inverted, double h, double t,
                               double dt_limit);
    /// The likely cause of a failure at substep length h, for the message.
    std::string likely_cause(const Scene& scene, double h, double dt_limit, const ContactResponse& contacts) const;

    double energy_ref() const { return m_energy_ref; }
    /// The energy the scene has to spend at the start: internal energy plus every free mass falling over the free
    /// vertices' span along gravity and down to the ground. The run's health and vbd's energy test measure
    /// against it.
    double energy_available() const { return m_energy_available; }

  private:
    double m_energy_ref = 0;
    double m_energy_available = 0;
    double m_msum = 0;
    Eigen::Vector3d m_centre0{0, 0, 0};
    double m_radius0 = 0;
    double m_speed_bound = 0;
    double m_inverted_since = -1;        ///< time at which more than 1 % of the tets became inverted (−1: not now)
    std::vector<double> m_object_height; ///< per object: extent along gravity at start (0: static or none)
};

/// Tets of the model's volume terms (the dynamic ones) whose signed volume at x is ≤ 0, by row, into `out`
/// (cleared first); returns their count. `volume`, when given, receives the sum of their signed volumes (the same
/// pass: what the run's health reads every step). Blocks of tets split over `threads`, joined in order: the same
/// list and sum at any thread count.
std::int64_t find_inverted_tets(const Model& model, const Positions& x, std::vector<std::int32_t>& out,
                                double* volume = nullptr, int threads = 1);

/// Short number for messages (3 significant digits).
std::string short_number(double v);

} // namespace tethash::sim
