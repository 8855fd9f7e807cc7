#pragma once
/// \file study/methods.hpp
/// The broad-phase methods side by side (detect.hpp: Method): the text grammar of their parameters, shared by
/// `tethash detect`, `tethash study method` and the benchmark, and one scene run by every method with the
/// contacts compared (`tethash detect --method all`).

#include "tethash/detect.hpp"
#include "tethash/error.hpp"

#include <span>
#include <string>
#include <vector>

namespace tethash::study {

/// Sets one partition parameter of `params` from its text: `option` is "--max-depth", "--leaf-size", "--levels"
/// (integers) or "--looseness" (a number); "default" (or "0") keeps the method's default. The value is checked
/// with the detector's own validation; throws Error "OPTION: ..." naming the text otherwise.
void parse_partition_param(const std::string& option, const std::string& text, DetectParams& params);

/// Whether `method` reads the partition parameter of `option` ("--max-depth": the trees and BVHs; "--leaf-size": the
/// same but the loose octree, which keeps each tet in the one cell it fits; "--looseness": the loose octree;
/// "--levels": the hierarchical grid).
bool method_uses(Method method, const std::string& option);

/// Methods of a comma-separated list: names of the grammar (detect_grammar.hpp: parse_method) or "all" (every method
/// but auto, in all_methods() order). Throws Error naming `option`.
std::vector<Method> parse_method_list(const std::string& text, const std::string& option = "--methods");

/// One method's run on a scene.
struct MethodRun {
    Method method = Method::hash;
    std::string error;          ///< not empty: the method threw (not built, refused the memory, ...); no stats
    DetectStats first;          ///< the first call (set-up included)
    DetectStats stats;          ///< the call of median total time
    std::vector<double> run_ms; ///< every timed call's total
    std::vector<Contact> contacts;
};

/// The scene of a comparison: positions, tets and objects as Detector::set_topology takes them.
struct CompareScene {
    PositionsRef positions;
    TetsRef tets;
    std::span<const Index> vertex_object, tet_object;
    std::span<const ObjectOptions> objects;
};

/// Runs each of `methods` on the scene with `params` (its method replaced): one untimed first call, then
/// `repeat` timed calls. A method that throws Error or runs out of memory gets its message in `error`.
std::vector<MethodRun> compare_methods(const CompareScene& scene, const DetectParams& params,
                                       std::span<const Method> methods, int repeat);

/// Whether every run without an error returned the same (vertex, tet) pairs as the first such run. `message` says
/// so in one line, or names the first method that differs and its missed and extra pairs.
struct Agreement {
    bool same = true;
    std::string message;
};
Agreement check_agreement(const std::vector<MethodRun>& runs);

/// The comparison as a text table: method, ms per stage (build = vertices, query = tets, exact = inside, sort),
/// total (median), candidates, memory, nodes, contacts; an erring method's row carries its message.
std::string method_table(const std::vector<MethodRun>& runs);

/// Bytes as "512 B", "3.2 kB", "14.1 MB", "1.5 GB".
std::string human_bytes(double bytes);

} // namespace tethash::study
