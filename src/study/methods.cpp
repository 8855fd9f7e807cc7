// The broad-phase methods side by side (methods.hpp).
#include "tethash/study/methods.hpp"
#include "tethash/detect_grammar.hpp"

#include "value_list.hpp"

#include "tethash/error.hpp"

#include <algorithm>
#include <cstdarg>
#include <cstdio>
#include <new>

namespace tethash::study {

namespace {

/// printf into a string (the study layer formats without fmt).
std::string format(const char* f, ...) __attribute__((format(printf, 1, 2)));
std::string format(const char* f, ...)
{
    char buf[512];
    va_list args;
    va_start(args, f);
    std::vsnprintf(buf, sizeof buf, f, args);
    va_end(args);
    return buf;
}

} // namespace

void parse_partition_param(const std::string& option, const std::string& text, DetectParams& params)
{
    PartitionParams& q = params.partition;
    const std::string t = trim(text);
    const bool keep = t == "default";
    if (option == "--max-depth")
        q.max_depth = keep ? 0 : static_cast<int>(std::clamp<long long>(parse_integer(t, option), -1, 1000));
    else if (option == "--leaf-size")
        q.leaf_size = keep ? 0 : static_cast<int>(std::clamp<long long>(parse_integer(t, option), -1, 1LL << 30));
    else if (option == "--levels")
        q.levels = keep ? 0 : static_cast<int>(std::clamp<long long>(parse_integer(t, option), -1, 1000));
    else if (option == "--looseness")
        q.looseness = keep ? 0 : parse_number(t, option);
    else
        throw Error("unknown partition parameter " + option);
    // 0 means "the method's default" inside DetectParams; written out it is more likely a mistake.
    if (!keep && ((option == "--max-depth" && q.max_depth == 0) || (option == "--leaf-size" && q.leaf_size == 0) ||
                  (option == "--levels" && q.levels == 0)))
        throw Error(option + " " + t + ": expected ≥ 1 (or 'default' for the method's default)");
    if (!keep && option == "--looseness" && q.looseness == 0)
        throw Error(option + " " + t + ": expected 1..16 (or 'default' for the method's default, 2)");
    try {
        Detector check(params); // the detector's own validation (no work)
    } catch (const Error& e) {
        throw Error(option + " " + t + ": " + e.what());
    }
}

bool method_uses(Method method, const std::string& option)
{
    // The methods that read each parameter (src/core/bp_*.cpp).
    static const std::vector<std::pair<std::string, std::vector<Method>>> readers = {
        {"--max-depth",
         {Method::octree, Method::octree_point, Method::octree_loose, Method::kd_tree, Method::kd_tree_point,
          Method::bsp_tree, Method::bsp_tree_balanced, Method::bvh, Method::bvh_refit}},
        {"--leaf-size",
         {Method::octree, Method::octree_point, Method::kd_tree, Method::kd_tree_point, Method::bsp_tree,
          Method::bsp_tree_balanced, Method::bvh, Method::bvh_refit, Method::portals}},
        {"--looseness", {Method::octree_loose}},
        {"--levels", {Method::hierarchical_grid}},
    };
    for (const auto& [name, methods] : readers)
        if (name == option) return std::find(methods.begin(), methods.end(), method) != methods.end();
    return false;
}

std::vector<Method> parse_method_list(const std::string& text, const std::string& option)
{
    std::vector<Method> out;
    for (const std::string& item : items_of({text}, option)) {
        if (item == "all") {
            for (Method m : all_methods())
                out.push_back(m);
        } else {
            out.push_back(parse_method(item, option));
        }
    }
    return out;
}

std::vector<MethodRun> compare_methods(const CompareScene& scene, const DetectParams& params,
                                       std::span<const Method> methods, int repeat)
{
    if (repeat < 1) throw Error("--repeat: expected ≥ 1, got " + std::to_string(repeat));
    std::vector<MethodRun> runs;
    for (Method m : methods) {
        MethodRun run;
        run.method = m;
        try {
            DetectParams p = params;
            p.method = m;
            Detector det(p);
            det.set_topology(scene.tets, static_cast<Index>(scene.positions.rows()), scene.vertex_object,
                             scene.tet_object, scene.objects);
            det.detect(scene.positions, &run.first);
            std::vector<DetectStats> all(static_cast<std::size_t>(repeat));
            for (DetectStats& s : all) {
                det.detect(scene.positions, &s);
                run.run_ms.push_back(s.ms_total);
            }
            std::vector<DetectStats> sorted = all;
            std::sort(sorted.begin(), sorted.end(),
                      [](const DetectStats& a, const DetectStats& b) { return a.ms_total < b.ms_total; });
            run.stats = sorted[sorted.size() / 2];
            run.contacts = det.contacts();
        } catch (const Error& e) {
            run.error = e.what();
        } catch (const std::bad_alloc&) {
            run.error = "out of memory";
        }
        runs.push_back(std::move(run));
    }
    return runs;
}

Agreement check_agreement(const std::vector<MethodRun>& runs)
{
    const MethodRun* ref = nullptr;
    int ran = 0;
    for (const MethodRun& r : runs) {
        if (!r.error.empty()) continue;
        ++ran;
        if (!ref) {
            ref = &r;
            continue;
        }
        std::int64_t missed = 0, extra = 0;
        std::size_t i = 0, j = 0;
        auto key = [](const Contact& c) { return std::pair<Index, Index>(c.vertex, c.tet); };
        while (i < r.contacts.size() || j < ref->contacts.size()) {
            if (j == ref->contacts.size() || (i < r.contacts.size() && key(r.contacts[i]) < key(ref->contacts[j]))) {
                ++extra;
                ++i;
            } else if (i == r.contacts.size() || key(ref->contacts[j]) < key(r.contacts[i])) {
                ++missed;
                ++j;
            } else {
                ++i;
                ++j;
            }
        }
        if (missed || extra)
            return {false,
                    format("methods disagree: %s returned %zu contacts, %s returned %zu (%lld missing, %lld extra)",
                           to_string(r.method), r.contacts.size(), to_string(ref->method), ref->contacts.size(),
                           static_cast<long long>(missed), static_cast<long long>(extra))};
    }
    const int failed = static_cast<int>(runs.size()) - ran;
    std::string msg = ran == 0
                          ? std::string("no method ran")
                          : format("all %d methods that ran returned the same %zu contacts", ran, ref->contacts.size());
    if (failed) msg += format(" (%d failed: see their rows)", failed);
    return {true, msg};
}

std::string human_bytes(double b)
{
    if (b < 1000) return format("%.0f B", b);
    if (b < 1e6) return format("%.1f kB", b / 1e3);
    if (b < 1e9) return format("%.1f MB", b / 1e6);
    return format("%.2f GB", b / 1e9);
}

std::string method_table(const std::vector<MethodRun>& runs)
{
    std::string out = format("%-13s %9s %9s %9s %9s %9s %12s %10s %9s %9s\n", "method", "build ms", "query ms",
                             "exact ms", "sort ms", "total ms", "candidates", "memory", "nodes", "contacts");
    for (const MethodRun& r : runs) {
        if (!r.error.empty()) {
            out += std::string(format("%-13s error: ", to_string(r.method))) + r.error + "\n";
            continue;
        }
        const DetectStats& s = r.stats;
        out += format("%-13s %9.3f %9.3f %9.3f %9.3f %9.3f %12lld %10s %9lld %9zu\n", to_string(r.method),
                      s.ms_vertices, s.ms_tets, s.ms_inside, s.ms_sort, s.ms_total,
                      static_cast<long long>(s.candidates), human_bytes(static_cast<double>(s.memory_bytes)).c_str(),
                      static_cast<long long>(s.nodes), r.contacts.size());
    }
    return out;
}

} // namespace tethash::study
