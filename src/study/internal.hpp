#pragma once
// Private parts of the study shared by study.cpp (detection sweeps, running, summary) and sim_study.cpp
// (integrator × dt × substeps).
#include "tethash/study/study.hpp"

#include "tethash/detect.hpp"

#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace tethash::study {

struct SceneData {
    std::string name;
    std::string source; ///< files or generator description
    TetMesh mesh;
    double mean_edge = 0;
    std::optional<std::vector<Contact>> oracle; ///< computed at the first point of the scene that needs it
    bool oracle_failed = false;
};

struct DetectPoint {
    std::size_t scene = 0;
    double cell_factor = 1;
    std::int64_t table_size = 0; ///< 0 = auto
    std::string table_kind;      ///< auto, given, pow2, prime
    std::string table_request;   ///< the spec item it came from
    HashFunction hash = HashFunction::column;
    int threads = 1;
};

struct SimPlan; // sim_study.cpp
struct SimPlanDeleter {
    void operator()(SimPlan* p) const;
};

struct StabilityPlan; // stability_study.cpp
struct StabilityPlanDeleter {
    void operator()(StabilityPlan* p) const;
};

struct StudyPlan {
    StudyOptions options;
    std::vector<std::string> columns;
    std::vector<PointInfo> points; ///< every point of the study, all shards
    std::vector<SceneData> scenes;
    std::vector<DetectPoint> detect_points;       ///< same indices as points (detection sweeps)
    std::unique_ptr<SimPlan, SimPlanDeleter> sim; ///< integrator sweep
    std::unique_ptr<StabilityPlan, StabilityPlanDeleter> stability; ///< stability sweep
    std::vector<std::string> notes;
};

/// Integrator sweep: fills plan.columns, plan.points and plan.sim from plan.options (throws Error on bad input).
void plan_sim_study(StudyPlan& plan);
/// Measures point `index` of an integrator sweep: returns its rows (one per repeat; fewer when stopped).
std::vector<Row> run_sim_point(StudyPlan& plan, std::int64_t index, const RunHooks& hooks);

/// Stability sweep (integrator × young × dt × mass ratio on two colliding copies of each --mesh).
void plan_stability_study(StudyPlan& plan);
std::vector<Row> run_stability_point(StudyPlan& plan, std::int64_t index, const RunHooks& hooks);

/// Helpers shared by the sweeps.
std::vector<double> parse_real_list(const std::vector<std::string>& specs, const std::string& option,
                                    double scale_for_x, bool log_ranges);
std::vector<int> parse_int_list(const std::vector<std::string>& specs, const std::string& option);
std::string json_escape(const std::string& s);
double elapsed_ms(std::int64_t start_ns);
std::int64_t now_ns();

} // namespace tethash::study
