#pragma once
// Measuring one point of a study (private): the detection sweeps (measure.cpp), the integrator sweep
// (sim_study.cpp) and the stability sweep (stability_study.cpp) each return a point's rows, one per repeat.
#include "plan.hpp"

#include <cstdint>
#include <string>
#include <vector>

namespace tethash::study {

/// The columns of a detection sweep's CSV (run_detect_point's rows).
std::vector<std::string> detect_columns();
/// Measures point `index` of a detection sweep; fewer rows than repeats when stopped.
std::vector<Row> run_detect_point(StudyPlan& plan, std::int64_t index, const RunHooks& hooks);
/// Measures point `index` of an integrator sweep.
std::vector<Row> run_sim_point(StudyPlan& plan, std::int64_t index, const RunHooks& hooks);
/// Measures point `index` of a stability sweep.
std::vector<Row> run_stability_point(StudyPlan& plan, std::int64_t index, const RunHooks& hooks);

/// A steady clock in nanoseconds, and the milliseconds since such a time.
std::int64_t now_ns();
double elapsed_ms(std::int64_t start_ns);

} // namespace tethash::study
