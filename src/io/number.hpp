#pragma once
// Private to tethash::io: numbers read from and written as text, the same way in every format.
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

namespace tethash::io::detail {

/// Parses a whole token as an integer (a leading '+' allowed; no fraction, no exponent); nullopt if it
/// is not one.
std::optional<std::int64_t> parse_int(std::string_view token);
/// Parses a whole token as a double (a leading '+' allowed; "nan"/"inf" parse; a value out of range
/// saturates to 0 or ±inf); nullopt if it is not one.
std::optional<double> parse_double(std::string_view token);

/// Shortest text that reads back as exactly `value` ("0.1", "1e-300", "nan").
std::string format_double(double value);
/// Appends format_double(value), or the integer, to `out`.
void append_double(std::string& out, double value);
void append_int(std::string& out, std::int64_t value);

/// A token as error messages show it: in single quotes, at most `limit` characters (then "..."),
/// bytes outside printable ASCII as \xNN.
std::string quote_token(std::string_view token, std::size_t limit);

/// `s` in lower case (ASCII).
std::string to_lower(std::string_view s);

} // namespace tethash::io::detail
