#pragma once
// The thread count of a simulation run left to choose (threads = 0): every core while they pay, one where they do
// not (private header).
//
// A step's result does not depend on its thread count (the detector, the sweeps and every reduction are ordered
// the same at any count), so the count may change from one step to the next at no cost to the answer. What more
// threads buy depends on the machine and on its load: on an idle machine two threads take a step in about three
// quarters of the time of one; on a machine whose cores are busy with other work a step's many short parallel
// regions each wait for a descheduled thread, and two threads took 5 to 10 times as long as one (docs/simulator.md
// has the figures). So the run keeps
// measuring: it starts on one thread, tries every core after a few steps, and now and then takes a few steps with
// the other count (a probe); the count with the shorter time per substep stays. A probe that loses waits twice as
// long before the next one (eight times when it took more than twice as long: a loaded machine), up to max_interval
// steps, so a run on a machine where the choice is clear pays a few steps in hundreds for knowing.
#include <cstdint>

namespace tethash::sim::detail {

class ThreadChoice {
  public:
    /// `most`: the most threads the run may use (every core); with 1 there is nothing to choose.
    explicit ThreadChoice(int most = 1);
    /// The threads OpenMP gives a parallel region (every core unless limited), 1 without OpenMP.
    static int every_core();

    /// The thread count of the next step.
    int threads() const { return m_now; }
    /// The step just taken with threads() threads took `ms_per_substep` (its wall time over its substeps).
    void record(double ms_per_substep);
    /// Times the run changed its count for good (a probe that won).
    std::int64_t switches() const { return m_switches; }

    static constexpr int first_probe = 4;   ///< steps before the first probe (a short run learns too)
    static constexpr int min_interval = 32; ///< steps between probes after one that won
    static constexpr int max_interval = 512;
    static constexpr int probe_steps = 2;   ///< a probe's steps: the first (the detector's lists rebuilt) not counted
    static constexpr double margin = 0.95;  ///< a probe wins when it takes less than this times the current time
    static constexpr double far_slower = 2; ///< a probe this many times slower backs off eight times, not two

  private:
    int m_most = 1;
    int m_kept = 1;        ///< the count that won the last comparison
    int m_now = 1;         ///< the count of the next step (m_kept, or the other one during a probe)
    double m_kept_ms = 0;  ///< running mean of the kept count's time per substep (0: none yet)
    double m_probe_ms = 0; ///< sum over the probe's counted steps
    int m_probe_step = 0;  ///< steps taken in the current probe (0: none running)
    int m_since = 0;       ///< steps since the last probe (or the start)
    int m_interval = first_probe;
    bool m_settle = true; ///< the first step after a change of count is not counted (caches, candidate lists)
    std::int64_t m_switches = 0;
};

} // namespace tethash::sim::detail
