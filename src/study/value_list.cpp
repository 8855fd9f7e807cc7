// The study's value lists (value_list.hpp): items, numbers, fractions, factors and log ranges.
#include "value_list.hpp"

#include "tethash/detect.hpp"
#include "tethash/detect_grammar.hpp"
#include "tethash/error.hpp"

#include <cmath>

namespace tethash::study {

std::vector<std::string> split(const std::string& s, char sep)
{
    std::vector<std::string> out;
    std::string cur;
    for (char c : s) {
        if (c == sep) {
            out.push_back(cur);
            cur.clear();
        } else {
            cur += c;
        }
    }
    out.push_back(cur);
    return out;
}

std::string trim(const std::string& s)
{
    const auto b = s.find_first_not_of(" \t");
    if (b == std::string::npos) return "";
    const auto e = s.find_last_not_of(" \t");
    return s.substr(b, e - b + 1);
}

/// All comma-separated items of all specs, trimmed; an empty item is an error.
std::vector<std::string> items_of(const std::vector<std::string>& specs, const std::string& option)
{
    std::vector<std::string> items;
    for (const auto& spec : specs)
        for (const auto& raw : split(spec, ',')) {
            const std::string it = trim(raw);
            if (it.empty()) throw Error(option + ": empty value in '" + spec + "'");
            items.push_back(it);
        }
    if (items.empty()) throw Error(option + ": empty list");
    return items;
}

namespace {

/// "xF" → F · scale (scale > 0), otherwise the number itself.
double parse_scaled(const std::string& text, const std::string& option, double scale)
{
    if (!text.empty() && text[0] == 'x') {
        if (scale <= 0) throw Error(option + ": 'x' factors are not allowed here, found '" + text + "'");
        return parse_number(text.substr(1), option) * scale;
    }
    // A fraction such as 1/240 (time steps are usually given so).
    if (const auto slash = text.find('/'); slash != std::string::npos) {
        const double den = parse_number(trim(text.substr(slash + 1)), option);
        if (!(den != 0)) throw Error(option + ": division by zero in '" + text + "'");
        return parse_number(trim(text.substr(0, slash)), option) / den;
    }
    return parse_number(text, option);
}

} // namespace

/// Log-spaced values from..to (points ≥ 1; one point: from, which must equal to).
std::vector<double> log_range(const std::string& item, const std::string& option, double scale)
{
    const auto parts = split(item, ':');
    if (parts.size() != 3) throw Error(option + ": expected FROM:TO:POINTS, found '" + item + "'");
    const double a = parse_scaled(trim(parts[0]), option, scale), b = parse_scaled(trim(parts[1]), option, scale);
    const long long n = parse_integer(trim(parts[2]), option);
    if (a <= 0 || b <= 0) throw Error(option + ": range '" + item + "' must have FROM > 0 and TO > 0");
    if (n < 1 || a > b || (n == 1 && a != b))
        throw Error(option + ": empty range '" + item + "' (need FROM <= TO and POINTS >= 1)");
    if (n > 100000) throw Error(option + ": range '" + item + "' has too many points");
    std::vector<double> v;
    for (long long i = 0; i < n; ++i)
        v.push_back(n == 1 ? a : a * std::pow(b / a, static_cast<double>(i) / static_cast<double>(n - 1)));
    return v;
}

std::vector<double> parse_real_list(const std::vector<std::string>& specs, const std::string& option,
                                    double scale_for_x, bool log_ranges)
{
    std::vector<double> out;
    for (const auto& it : items_of(specs, option)) {
        if (it.find(':') != std::string::npos) {
            if (!log_ranges) throw Error(option + ": ranges are not allowed here, found '" + it + "'");
            for (double v : log_range(it, option, scale_for_x))
                out.push_back(v);
        } else {
            const double v = parse_scaled(it, option, scale_for_x);
            if (!(v > 0)) throw Error(option + ": value " + it + " must be > 0");
            out.push_back(v);
        }
    }
    return out;
}

std::vector<int> parse_int_list(const std::vector<std::string>& specs, const std::string& option)
{
    std::vector<int> out;
    for (const auto& it : items_of(specs, option)) {
        const auto parts = split(it, ':');
        if (parts.size() == 1) {
            const long long v = parse_integer(it, option);
            if (v < 1 || v > 1000000) throw Error(option + ": value " + it + " must be >= 1");
            out.push_back(static_cast<int>(v));
        } else if (parts.size() == 2) {
            const long long a = parse_integer(trim(parts[0]), option), b = parse_integer(trim(parts[1]), option);
            if (a < 1 || b < a || b > 1000000)
                throw Error(option + ": empty range '" + it + "' (need 1 <= FROM <= TO)");
            for (long long v = a; v <= b; ++v)
                out.push_back(static_cast<int>(v));
        } else {
            throw Error(option + ": expected N or FROM:TO, found '" + it + "'");
        }
    }
    return out;
}

} // namespace tethash::study
