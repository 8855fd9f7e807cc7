#pragma once
// The grammar of the study's value lists (spec.hpp): comma-separated items, each a single value in the grammar
// of every command (detect_grammar.hpp for the detector's parameters; numbers: its parse_number and
// parse_integer) or a range. Shared by every sweep.
#include <string>
#include <vector>

namespace tethash::study {

/// `s` cut at every `sep` (empty pieces kept).
std::vector<std::string> split(const std::string& s, char sep);
/// `s` without leading and trailing blanks.
std::string trim(const std::string& s);
/// All comma-separated items of all specs, trimmed. Throws Error naming `option` on an empty item or list.
std::vector<std::string> items_of(const std::vector<std::string>& specs, const std::string& option);

/// Log-spaced values FROM..TO ("FROM:TO:POINTS", POINTS ≥ 1; one point: FROM, which must equal TO), each end
/// a number, "xF" (F · scale, scale > 0) or a fraction "A/B".
std::vector<double> log_range(const std::string& item, const std::string& option, double scale);

/// Positive reals: numbers, fractions "1/240", "xF" (F · scale_for_x; an error when scale_for_x ≤ 0) and, with
/// `log_ranges`, FROM:TO:POINTS.
std::vector<double> parse_real_list(const std::vector<std::string>& specs, const std::string& option,
                                    double scale_for_x, bool log_ranges);
/// Counts ≥ 1: N or FROM:TO (every count in between).
std::vector<int> parse_int_list(const std::vector<std::string>& specs, const std::string& option);

} // namespace tethash::study
