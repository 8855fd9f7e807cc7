// tethash ccd FILE.csv... --type vertex-face|edge-edge [--json]: runs the continuous queries (tethash/ccd.hpp) on
// query files of the CCD benchmark of Wang et al. 2021 (tethash/io/ccd_queries.hpp) and reports false negatives,
// false positives and the mean time per query on one thread.
#include "command.hpp"

#include "tethash/ccd.hpp"
#include "tethash/error.hpp"
#include "tethash/io/ccd_queries.hpp"
#include "tethash/study/json.hpp"

#include <fmt/format.h>

#include <ctime>
#include <memory>
#include <string>
#include <vector>

namespace tethash::cli {
namespace {

struct CcdOptions {
    std::vector<std::string> files;
    std::string type;
    bool json = false;
    double tolerance = ccd::CcdParams{}.tolerance;
    std::int64_t max_iterations = ccd::CcdParams{}.max_iterations;
};

struct FileTally {
    std::string path;
    std::int64_t queries = 0, colliding = 0, false_negatives = 0, false_positives = 0;
    double seconds = 0;               ///< CPU time of the queries (this thread)
    std::vector<std::int64_t> missed; ///< first lines of the false negatives
};

/// CPU time of the calling thread, in seconds: the queries' own cost on one core, not the machine's other load.
double thread_seconds()
{
    timespec ts{};
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
    return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

void run_ccd(const CcdOptions& o)
{
    if (o.type != "vertex-face" && o.type != "edge-edge")
        throw Error("--type: expected 'vertex-face' or 'edge-edge', got '" + o.type + "'");
    const bool edge_edge = o.type == "edge-edge";
    ccd::CcdParams params;
    params.tolerance = o.tolerance;
    params.max_iterations = o.max_iterations;
    if (!(params.tolerance > 0 && params.tolerance < 1e300))
        throw Error(fmt::format("--tolerance: expected a positive finite number, got {}", o.tolerance));
    if (params.max_iterations < 1)
        throw Error(fmt::format("--max-iterations: expected at least 1, got {}", o.max_iterations));
    // Every file is read and checked before any query runs.
    std::vector<std::vector<io::CcdQuery>> sets;
    sets.reserve(o.files.size());
    for (const auto& path : o.files)
        sets.push_back(io::read_ccd_queries(path));

    std::vector<FileTally> tallies;
    for (std::size_t f = 0; f < sets.size(); ++f) {
        FileTally t;
        t.path = o.files[f];
        std::vector<char> hits(sets[f].size());
        const double start = thread_seconds();
        for (std::size_t q = 0; q < sets[f].size(); ++q) {
            const auto& x = sets[f][q].points;
            const ccd::CcdResult r = edge_edge
                                         ? ccd::edge_edge_ccd(x[0], x[1], x[2], x[3], x[4], x[5], x[6], x[7], params)
                                         : ccd::vertex_face_ccd(x[0], x[1], x[2], x[3], x[4], x[5], x[6], x[7], params);
            hits[q] = r.hit;
        }
        t.seconds = thread_seconds() - start;
        for (std::size_t q = 0; q < sets[f].size(); ++q) {
            const bool truth = sets[f][q].collides;
            ++t.queries;
            t.colliding += truth;
            if (truth && !hits[q]) {
                ++t.false_negatives;
                t.missed.push_back(sets[f][q].line);
            }
            t.false_positives += !truth && hits[q];
        }
        tallies.push_back(std::move(t));
    }
    FileTally total;
    total.path = "total";
    for (const auto& t : tallies) {
        total.queries += t.queries;
        total.colliding += t.colliding;
        total.false_negatives += t.false_negatives;
        total.false_positives += t.false_positives;
        total.seconds += t.seconds;
    }
    const auto ns_per_query = [](const FileTally& t) {
        return t.queries ? 1e9 * t.seconds / static_cast<double>(t.queries) : 0.0;
    };
    if (o.json) {
        study::JsonWriter j;
        j.begin_object();
        j.key("type").value(o.type);
        j.key("tolerance").value(params.tolerance);
        j.key("max_iterations").value(params.max_iterations);
        j.key("queries").value(total.queries);
        j.key("colliding").value(total.colliding);
        j.key("false_negatives").value(total.false_negatives);
        j.key("false_positives").value(total.false_positives);
        j.key("ns_per_query").value(ns_per_query(total));
        j.key("files").begin_array(study::JsonWriter::block_layout);
        for (const auto& t : tallies) {
            j.begin_object(study::JsonWriter::inline_layout);
            j.key("path").value(t.path);
            j.key("queries").value(t.queries);
            j.key("colliding").value(t.colliding);
            j.key("false_negatives").value(t.false_negatives);
            j.key("false_positives").value(t.false_positives);
            j.key("ns_per_query").value(ns_per_query(t));
            j.key("missed_lines").begin_array();
            for (const auto line : t.missed)
                j.value(line);
            j.end_array();
            j.end_object();
        }
        j.end_array();
        j.end_object();
        fmt::print("{}\n", j.str());
    } else {
        for (const auto& t : tallies) {
            fmt::print("{}: {} queries ({} colliding), {} false negatives, {} false positives, {:.0f} ns per query\n",
                       t.path, t.queries, t.colliding, t.false_negatives, t.false_positives, ns_per_query(t));
            for (const auto line : t.missed)
                fmt::print("  false negative: {}:{}\n", t.path, line);
        }
        if (tallies.size() > 1)
            fmt::print("total: {} queries ({} colliding), {} false negatives, {} false positives, {:.0f} ns per "
                       "query\n",
                       total.queries, total.colliding, total.false_negatives, total.false_positives,
                       ns_per_query(total));
    }
    if (total.false_negatives)
        throw RunFailure(fmt::format("{} false negatives (a contact reported as none)", total.false_negatives));
}

const Registrar reg{
    {"ccd",
     "Continuous collision queries of the CCD benchmark's files (Wang et al. 2021): false negatives and positives "
     "against their ground truth, time per query",
     [](CLI::App& sub) {
         auto o = std::make_shared<CcdOptions>();
         sub.add_option("FILE", o->files,
                        "Query files (CSV, 8 rows per query, each row x, y, z as numerator,denominator pairs and the "
                        "ground truth 0 or 1 in column 7)")
             ->required();
         sub.add_option("--type", o->type,
                        "vertex-face (rows: vertex, face corners 0-2 at t = 0, then at t = 1) or edge-edge (rows: "
                        "edge a's ends, edge b's ends at t = 0, then at t = 1)")
             ->required();
         sub.add_flag("--json", o->json,
                      "JSON on standard output: queries, colliding, false_negatives, false_positives, ns_per_query "
                      "(totals) and the same per file");
         sub.add_option("--tolerance", o->tolerance,
                        "Range width (coordinates' units) below which a box of the search counts as a contact")
             ->capture_default_str();
         sub.add_option("--max-iterations", o->max_iterations,
                        "Boxes one query examines at most; reaching it reports a contact")
             ->capture_default_str();
         sub.footer("Times are CPU time of one thread per query, reading and checking excluded. Exit status 1 when "
                    "a query that collides is reported as not colliding (a false negative), 2 on bad input.");
         sub.callback([o] { run_ccd(*o); });
     }}};

} // namespace
} // namespace tethash::cli
