#pragma once
// `tethash simulate --ccd-queries DIR`: the continuous queries of the run's steps (the boundary vertex-face and
// edge-edge pairs whose swept boxes overlap, tethash/continuous.hpp's candidates) in the query format of the CCD
// benchmark (tethash/io/ccd_queries.hpp), for `tethash ccd` to replay and time; called by simulate.cpp.
#include "tethash/io/ccd_queries.hpp"
#include "tethash/mesh.hpp"

#include <cstdint>
#include <string>
#include <vector>

namespace tethash::cli {

struct CcdQueryOptions {
    std::string dir;                    ///< "" = off; else DIR/vertex_face.csv and DIR/edge_edge.csv
    std::string steps;                  ///< "" = every step; "K" or "FIRST:LAST" (1-based, inclusive)
    std::int64_t max_queries = 1000000; ///< per file, whole steps only
};

/// Collects the queries of the selected steps in memory and writes both files at the end (atomically).
class CcdQueryRecorder {
  public:
    /// Checks the options and that both files can be created (Error: bad option or path, exit 2; WriteError: the
    /// file system refuses, exit 1), before the run.
    explicit CcdQueryRecorder(const CcdQueryOptions& o);
    bool on() const { return !m_dir.empty(); }
    /// Whether step `step` (1-based) is to be recorded (selected, and the cap not yet reached).
    bool wants(int step) const;
    /// Records the candidates of step `step` from x0 to x1, their ground truth the narrow phase's answer; a step
    /// that would take a file past the cap is left out, and so is every later step.
    void record(int step, const TetsRef& tets, const PositionsRef& x0, const PositionsRef& x1);
    /// Writes both files (all or none) and prints what they hold.
    void write() const;

  private:
    std::string m_dir;
    int m_first = 1, m_last = 0; ///< m_last 0: no end
    std::int64_t m_max = 0;
    bool m_capped = false;
    int m_capped_at = 0;
    int m_recorded_first = 0, m_recorded_last = 0, m_recorded_steps = 0;
    std::vector<io::CcdQuery> m_vertex_face, m_edge_edge;
};

} // namespace tethash::cli
