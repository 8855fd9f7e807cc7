#include "number.hpp"

#include <cctype>
#include <charconv>
#include <cstdlib>
#include <system_error>

namespace tethash::io::detail {

std::optional<std::int64_t> parse_int(std::string_view token)
{
    if (!token.empty() && token.front() == '+') token.remove_prefix(1);
    if (token.empty()) return std::nullopt;
    std::int64_t value = 0;
    const auto [ptr, ec] = std::from_chars(token.data(), token.data() + token.size(), value);
    if (ec != std::errc() || ptr != token.data() + token.size()) return std::nullopt;
    return value;
}

std::optional<double> parse_double(std::string_view token)
{
    if (!token.empty() && token.front() == '+') token.remove_prefix(1);
    if (token.empty()) return std::nullopt;
    double value = 0;
    const auto [ptr, ec] = std::from_chars(token.data(), token.data() + token.size(), value);
    if (ptr != token.data() + token.size()) return std::nullopt;
    // Denormal or huge: let strtod decide (it gives 0 or ±HUGE_VAL, which finite checks catch).
    if (ec == std::errc::result_out_of_range) return std::strtod(std::string(token).c_str(), nullptr);
    if (ec != std::errc()) return std::nullopt;
    return value;
}

std::string format_double(double value)
{
    char buf[64];
    const auto [ptr, ec] = std::to_chars(buf, buf + sizeof buf, value);
    return ec == std::errc() ? std::string(buf, ptr) : std::string("nan");
}

void append_double(std::string& out, double value)
{
    out += format_double(value);
}

void append_int(std::string& out, std::int64_t value)
{
    char buf[32];
    const auto [ptr, ec] = std::to_chars(buf, buf + sizeof buf, value);
    (void)ec; // 32 characters hold every int64
    out.append(buf, ptr);
}

std::string to_lower(std::string_view s)
{
    std::string r(s);
    for (char& c : r)
        c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    return r;
}

std::string quote_token(std::string_view token, std::size_t limit)
{
    std::string s = "'";
    for (std::size_t i = 0; i < token.size() && i < limit; ++i) {
        const auto c = static_cast<unsigned char>(token[i]);
        if (c >= 32 && c < 127) {
            s += static_cast<char>(c);
        } else {
            static const char* hex = "0123456789abcdef";
            s += "\\x";
            s += hex[c >> 4];
            s += hex[c & 15];
        }
    }
    if (token.size() > limit) s += "...";
    s += "'";
    return s;
}

} // namespace tethash::io::detail
