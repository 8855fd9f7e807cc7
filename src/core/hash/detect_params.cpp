// The text grammar of the detector's parameters (detect.hpp): the one parser behind every command's
// --cell-size, --table-size, --threads and --skin, so that a value means the same thing everywhere.
#include "../enum_names.hpp"
#include "detect_checks.hpp"
#include "hash_grid.hpp"
#include "tethash/detect.hpp"
#include "tethash/error.hpp"
#include "tethash/portals.hpp"

#include <algorithm>
#include <array>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <sstream>
#include <thread>

namespace tethash {
namespace {

/// A whole-string decimal number, or false.
bool to_double(const std::string& text, double& out)
{
    if (text.empty() || std::isspace(static_cast<unsigned char>(text[0]))) return false;
    char* end = nullptr;
    out = std::strtod(text.c_str(), &end);
    return end == text.c_str() + text.size() && std::isfinite(out);
}

/// A whole-string decimal integer, or false.
bool to_integer(const std::string& text, long long& out)
{
    if (text.empty() || std::isspace(static_cast<unsigned char>(text[0]))) return false;
    char* end = nullptr;
    errno = 0;
    out = std::strtoll(text.c_str(), &end, 10);
    return end == text.c_str() + text.size() && errno == 0;
}

/// Splits "xF" into (true, "F"); anything else into (false, text).
std::pair<bool, std::string> factor_form(const std::string& text)
{
    if (!text.empty() && (text[0] == 'x' || text[0] == 'X')) return {true, text.substr(1)};
    return {false, text};
}

} // namespace

double parse_number(const std::string& text, const std::string& option)
{
    double v = 0;
    if (!to_double(text, v)) throw Error(option + ": expected a number, found '" + text + "'");
    return v;
}

long long parse_integer(const std::string& text, const std::string& option)
{
    long long v = 0;
    if (!to_integer(text, v)) throw Error(option + ": expected an integer, found '" + text + "'");
    return v;
}

int max_threads()
{
    const unsigned hw = std::thread::hardware_concurrency();
    return std::max(256, static_cast<int>(std::min(hw, 1u << 20)));
}

int check_threads(long long threads, const std::string& option)
{
    if (threads < 0 || threads > max_threads())
        throw Error(option + " " + std::to_string(threads) + ": expected 0 (every hardware thread) or 1.." +
                    std::to_string(max_threads()) + " (this machine has " +
                    std::to_string(std::max(1u, std::thread::hardware_concurrency())) + " hardware threads)");
    return static_cast<int>(threads);
}

int parse_threads(const std::string& text, const std::string& option)
{
    long long v = 0;
    if (!to_integer(text, v))
        throw Error(option + ": expected a thread count (0 = every hardware thread, 1.." +
                    std::to_string(max_threads()) + "), found '" + text + "'");
    return check_threads(v, option);
}

void parse_cell_size(const std::string& text, DetectParams& params, const std::string& option)
{
    if (text == "auto") {
        params.cell_size_mode = DetectParams::CellSizeMode::auto_mean_edge;
        params.cell_size = 1.0;
        return;
    }
    const auto [factor, number] = factor_form(text);
    double v = 0;
    if (!to_double(number, v) || !(v > 0))
        throw Error(option + ": expected a length L > 0, 'xF' (F > 0 times the mean edge length) or 'auto', found '" +
                    text + "'");
    params.cell_size_mode =
        factor ? DetectParams::CellSizeMode::factor_of_mean_edge : DetectParams::CellSizeMode::absolute;
    params.cell_size = v;
}

std::int64_t next_power_of_two(std::int64_t n)
{
    std::int64_t p = 1;
    while (p < n && p < (std::int64_t{1} << 62))
        p <<= 1;
    return p;
}

std::int64_t parse_table_size(const std::string& text, std::int64_t vertices, const std::string& option)
{
    if (text == "auto") return 0;
    const auto [factor, number] = factor_form(text);
    const std::string expected = option + ": expected N (1.." + std::to_string(max_table_size) +
                                 " buckets), 'xF' (F > 0 times the vertex count, rounded up to a power of two) or "
                                 "'auto', found '" +
                                 text + "'";
    std::int64_t size = 0;
    if (factor) {
        double f = 0;
        if (!to_double(number, f) || !(f > 0)) throw Error(expected);
        const double want = std::ceil(f * static_cast<double>(std::max<std::int64_t>(vertices, 1)));
        if (vertices > 0 && !(want <= static_cast<double>(max_table_size)))
            throw Error(option + " " + text + ": " + std::to_string(vertices) + " vertices × " + number +
                        " is more than the largest table (" + std::to_string(max_table_size) + " buckets)");
        size = next_power_of_two(std::max<std::int64_t>(1, static_cast<std::int64_t>(std::min(want, 1e18))));
    } else {
        long long n = 0;
        if (!to_integer(number, n) || n < 1 || n > max_table_size) throw Error(expected);
        size = n;
    }
    return std::min(size, max_table_size);
}

void parse_skin(const std::string& text, DetectParams& params, const std::string& option)
{
    const auto [factor, number] = factor_form(text);
    double v = 0;
    if (!to_double(number, v) || !(v >= 0))
        throw Error(option + ": expected a length ≥ 0 or 'xF' (F ≥ 0 times the cell size), found '" + text + "'");
    params.skin_mode = factor ? DetectParams::SkinMode::factor_of_cell_size : DetectParams::SkinMode::absolute;
    params.skin = v;
}

namespace {
constexpr detail::EnumName<HashFunction> k_hash_names[] = {{HashFunction::teschner, "teschner"},
                                                           {HashFunction::column, "column"}};

constexpr detail::EnumName<Method> k_method_names[] = {
    {Method::hash, "hash"},
    {Method::brute_force, "brute"},
    {Method::uniform_grid, "grid"},
    {Method::hierarchical_grid, "hgrid"},
    {Method::octree, "octree"},
    {Method::octree_point, "octree-point"},
    {Method::octree_loose, "octree-loose"},
    {Method::kd_tree, "kd"},
    {Method::kd_tree_point, "kd-point"},
    {Method::bsp_tree, "bsp"},
    {Method::bsp_tree_balanced, "bsp-balanced"},
    {Method::sort_sweep, "sort-sweep"},
    {Method::bvh, "bvh"},
    {Method::bvh_refit, "bvh-refit"},
    {Method::portals, "portals"},
    {Method::automatic, "auto"},
};
constexpr std::size_t k_num_methods = sizeof k_method_names / sizeof k_method_names[0];

// The methods in the order of k_method_names, without `automatic` (the last entry).
constexpr auto k_method_list = [] {
    std::array<Method, k_num_methods - 1> out{};
    for (std::size_t k = 0; k + 1 < k_num_methods; ++k)
        out[k] = k_method_names[k].value;
    return out;
}();

} // namespace

Method parse_method(const std::string& text, const std::string& option)
{
    if (const auto m = detail::value_named(k_method_names, text)) return *m;
    std::string names;
    for (const auto& row : k_method_names)
        names += names.empty() ? row.name : std::string(", ") + row.name;
    throw Error(option + ": unknown method '" + text + "' (expected one of " + names + ")");
}

const char* to_string(Method m)
{
    return detail::name_of(k_method_names, m);
}

std::span<const Method> all_methods()
{
    return k_method_list;
}

HashFunction parse_hash_function(const std::string& name)
{
    if (const auto h = detail::value_named(k_hash_names, name)) return *h;
    throw Error("unknown hash function '" + name + "' (expected teschner or column)");
}

const char* to_string(HashFunction h)
{
    return detail::name_of(k_hash_names, h);
}

namespace detail {

void validate_params(const DetectParams& p)
{
    using Mode = DetectParams::CellSizeMode;
    if (p.cell_size_mode == Mode::absolute && !(p.cell_size > 0 && std::isfinite(p.cell_size)))
        throw Error("cell_size must be positive and finite, got " + std::to_string(p.cell_size));
    if (p.cell_size_mode == Mode::factor_of_mean_edge && !(p.cell_size > 0 && std::isfinite(p.cell_size)))
        throw Error("cell_size factor must be positive and finite, got " + std::to_string(p.cell_size));
    if (p.table_size < 0)
        throw Error("table_size must be ≥ 1 (or 0 for automatic), got " + std::to_string(p.table_size));
    if (p.table_size > max_table_size)
        throw Error("table_size " + std::to_string(p.table_size) + " is too large (at most " +
                    std::to_string(max_table_size) + ")");
    check_threads(p.threads, "threads");
    if (!(p.skin >= 0) || !std::isfinite(p.skin)) {
        std::ostringstream s;
        s << "skin must be ≥ 0 and finite (0 = no candidate reuse), got " << p.skin;
        throw Error(s.str());
    }
    if (p.skin_mode != DetectParams::SkinMode::absolute && p.skin_mode != DetectParams::SkinMode::factor_of_cell_size)
        throw Error("skin mode out of range: " + std::to_string(static_cast<int>(p.skin_mode)));
    if (p.hash != HashFunction::teschner && p.hash != HashFunction::column)
        throw Error("hash function out of range: " + std::to_string(static_cast<int>(p.hash)));
    if (std::string(to_string(p.method)) == "?")
        throw Error("method out of range: " + std::to_string(static_cast<int>(p.method)));
    const PartitionParams& q = p.partition;
    if (q.max_depth < 0 || q.max_depth > 30)
        throw Error("max_depth must be 1..30 (or 0 for the method's default), got " + std::to_string(q.max_depth));
    if (q.leaf_size < 0)
        throw Error("leaf_size must be ≥ 1 (or 0 for the method's default), got " + std::to_string(q.leaf_size));
    if (!(q.looseness == 0 || (q.looseness >= 1 && q.looseness <= 16))) {
        std::ostringstream s;
        s << "looseness must be 1..16 (or 0 for the default 2), got " << q.looseness;
        throw Error(s.str());
    }
    if (q.levels < 0 || q.levels > 32)
        throw Error("levels must be 1..32 (or 0 for as many as the tet sizes span), got " + std::to_string(q.levels));
    if (q.cells) check_cell_layout(*q.cells);
}

} // namespace detail

} // namespace tethash
