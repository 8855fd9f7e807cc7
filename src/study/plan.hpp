#pragma once
// The plan of a study (private): its scenes and every point, expanded from the options (spec.hpp) by
// plan.cpp (detection sweeps), sim_study.cpp (integrator × dt × substeps) and stability_study.cpp; measured
// by measure.hpp.
#include "tethash/study/study.hpp"

#include "tethash/detect.hpp"
#include "tethash/portals.hpp"

#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace tethash::study {

struct SceneData {
    std::string kind; ///< "mesh", "teschner" or "partition" (the space-partition comparison's scenes)
    std::string name;
    std::string source; ///< files or generator description
    TetMesh mesh;
    double mean_edge = 0;
    std::optional<std::vector<Contact>> oracle; ///< computed at the first point of the scene that needs it
    std::shared_ptr<const CellLayout> cells;    ///< the scene's cells and portals (Method::portals), or null
};

struct DetectPoint {
    std::size_t scene = 0;
    double cell_factor = 1;
    std::int64_t table_size = 0; ///< 0 = auto
    std::string table_kind;      ///< auto, given, pow2, prime
    std::string table_request;   ///< the spec item it came from
    HashFunction hash = HashFunction::column;
    int threads = 1;
    Method method = Method::hash;
    PartitionParams partition;
    /// The partition parameters as the CSV shows them ("max_depth", ... in partition_columns() order): the value,
    /// "default", or "" where the method does not read it.
    std::vector<std::string> partition_text;
};

/// The columns of the partition parameters and their options: max_depth --max-depth, leaf_size --leaf-size,
/// looseness --looseness, levels --levels.
const std::vector<std::pair<std::string, std::string>>& partition_columns();

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
    std::vector<DetectPoint> detect_points;                         ///< same indices as points (detection sweeps)
    std::unique_ptr<SimPlan, SimPlanDeleter> sim;                   ///< integrator sweep
    std::unique_ptr<StabilityPlan, StabilityPlanDeleter> stability; ///< stability sweep
    std::vector<std::string> notes;
};

/// Detection sweeps (cell size, table size, hash, threads, grid): scenes, columns and points from plan.options.
void plan_detection_study(StudyPlan& plan);
/// Integrator sweep: fills plan.columns, plan.points and plan.sim from plan.options (throws Error on bad input).
void plan_sim_study(StudyPlan& plan);
/// Stability sweep (integrator × young × dt × mass ratio on two colliding copies of each --mesh).
void plan_stability_study(StudyPlan& plan);

} // namespace tethash::study
