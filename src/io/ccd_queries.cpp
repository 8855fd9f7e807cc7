// Reader of the CCD benchmark's query files (include/tethash/io/ccd_queries.hpp).
//
// Rationals to doubles, correctly rounded: numerator and denominator are parsed into unsigned big integers
// (base 2^32 limbs); the quotient is taken by binary long division to 55 significant bits plus a sticky bit
// (whether the remainder is nonzero), which rounds to nearest-even at 53 bits exactly, or at fewer bits in the
// subnormal range, so the result is the double nearest the rational (no intermediate rounding).
#include "tethash/io/ccd_queries.hpp"

#include "tethash/error.hpp"
#include "tethash/io/file.hpp"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <string>
#include <utility>

namespace tethash::io {
namespace {

/// An unsigned integer, limbs of 32 bits, least significant first, no leading zero limbs (zero: no limbs).
struct BigUint {
    std::vector<std::uint32_t> limb;

    void trim()
    {
        while (!limb.empty() && limb.back() == 0)
            limb.pop_back();
    }
    bool zero() const { return limb.empty(); }
    std::int64_t bits() const
    {
        if (limb.empty()) return 0;
        std::int64_t n = 32 * static_cast<std::int64_t>(limb.size() - 1);
        for (std::uint32_t top = limb.back(); top; top >>= 1)
            ++n;
        return n;
    }
    void shift_left(std::int64_t s)
    {
        if (zero() || s == 0) return;
        const std::size_t whole = static_cast<std::size_t>(s / 32);
        const int part = static_cast<int>(s % 32);
        std::vector<std::uint32_t> out(limb.size() + whole + 1, 0);
        for (std::size_t i = 0; i < limb.size(); ++i) {
            const std::uint64_t v = static_cast<std::uint64_t>(limb[i]) << part;
            out[i + whole] |= static_cast<std::uint32_t>(v);
            out[i + whole + 1] |= static_cast<std::uint32_t>(v >> 32);
        }
        limb = std::move(out);
        trim();
    }
    /// -1, 0, +1 as *this <, ==, > o.
    int compare(const BigUint& o) const
    {
        if (limb.size() != o.limb.size()) return limb.size() < o.limb.size() ? -1 : 1;
        for (std::size_t i = limb.size(); i-- > 0;)
            if (limb[i] != o.limb[i]) return limb[i] < o.limb[i] ? -1 : 1;
        return 0;
    }
    /// *this -= o, requires *this >= o.
    void subtract(const BigUint& o)
    {
        std::int64_t borrow = 0;
        for (std::size_t i = 0; i < limb.size(); ++i) {
            std::int64_t d = static_cast<std::int64_t>(limb[i]) - borrow - (i < o.limb.size() ? o.limb[i] : 0);
            borrow = d < 0;
            if (d < 0) d += std::int64_t(1) << 32;
            limb[i] = static_cast<std::uint32_t>(d);
        }
        trim();
    }
    /// *this = *this · 10 + digit.
    void times10_plus(std::uint32_t digit)
    {
        std::uint64_t carry = digit;
        for (std::uint32_t& l : limb) {
            const std::uint64_t v = static_cast<std::uint64_t>(l) * 10 + carry;
            l = static_cast<std::uint32_t>(v);
            carry = v >> 32;
        }
        if (carry) limb.push_back(static_cast<std::uint32_t>(carry));
    }
};

/// Parses [+-]digits; `negative` gets the sign. Throws Error naming the text.
BigUint parse_integer(std::string_view text, bool& negative, const char* what)
{
    negative = false;
    std::size_t i = 0;
    if (!text.empty() && (text[0] == '-' || text[0] == '+')) {
        negative = text[0] == '-';
        i = 1;
    }
    if (i == text.size())
        throw Error(std::string("expected an integer ") + what + ", found '" + std::string(text) + "'");
    BigUint n;
    for (; i < text.size(); ++i) {
        const char c = text[i];
        if (c < '0' || c > '9')
            throw Error(std::string("expected an integer ") + what + ", found '" + std::string(text) + "'");
        n.times10_plus(static_cast<std::uint32_t>(c - '0'));
    }
    n.trim();
    return n;
}

std::string_view trim_blanks(std::string_view s)
{
    while (!s.empty() && (s.front() == ' ' || s.front() == '\t'))
        s.remove_prefix(1);
    while (!s.empty() && (s.back() == ' ' || s.back() == '\t' || s.back() == '\r'))
        s.remove_suffix(1);
    return s;
}

} // namespace

double rational_to_double(std::string_view num_text, std::string_view den_text)
{
    bool negative = false, den_negative = false;
    BigUint num = parse_integer(trim_blanks(num_text), negative, "numerator");
    BigUint den = parse_integer(trim_blanks(den_text), den_negative, "denominator");
    if (den.zero()) throw Error("zero denominator");
    if (den_negative) throw Error("negative denominator '" + std::string(den_text) + "'");
    if (num.zero()) return negative ? -0.0 : 0.0;
    // Scale so that q = floor(num 2^s / den) has 55 or 56 bits: 2^(nb-1) <= num < 2^nb, likewise den, so
    // num 2^s / den lies in (2^(nb+s-db-1), 2^(nb+s-db+1)); s = 55 - nb + db gives q in [2^54, 2^56).
    const std::int64_t s = 55 - num.bits() + den.bits();
    if (s > 0)
        num.shift_left(s);
    else
        den.shift_left(-s);
    std::uint64_t q = 0;
    for (int bit = 56; bit >= 0; --bit) {
        BigUint d = den;
        d.shift_left(bit);
        if (num.compare(d) >= 0) {
            num.subtract(d);
            q |= std::uint64_t(1) << bit;
        }
    }
    const bool sticky = !num.zero();
    // The value is (q + f) 2^-s with 0 <= f < 1 (f > 0 iff sticky); q has qb bits, its leading bit at 2^(qb-1-s).
    int qb = 0;
    for (std::uint64_t v = q; v; v >>= 1)
        ++qb;
    const std::int64_t exponent = qb - 1 - s; // of the leading bit
    // Keep 53 bits, fewer below the normal range (the last subnormal bit is 2^-1074).
    std::int64_t keep = 53;
    if (exponent < -1022) keep = 53 - (-1022 - exponent);
    if (keep < 0) return negative ? -0.0 : 0.0; // below 2^-1075: nearer zero than the smallest subnormal
    const std::int64_t drop = qb - keep;        // 2 <= drop <= 56
    std::uint64_t kept = q >> drop;
    const std::uint64_t rest = q & ((std::uint64_t(1) << drop) - 1), half = std::uint64_t(1) << (drop - 1);
    if (rest > half || (rest == half && (sticky || (kept & 1)))) ++kept;
    const double value = std::ldexp(static_cast<double>(kept), static_cast<int>(drop - s));
    if (!std::isfinite(value)) throw Error("value out of the range of double");
    return negative ? -value : value;
}

std::vector<CcdQuery> parse_ccd_queries(const std::string& path, std::string_view text)
{
    std::vector<CcdQuery> queries;
    CcdQuery current;
    int row = 0;
    std::int64_t line_no = 0;
    std::size_t pos = 0;
    while (pos < text.size()) {
        std::size_t end = text.find('\n', pos);
        if (end == std::string_view::npos) end = text.size();
        const std::string_view line = trim_blanks(text.substr(pos, end - pos));
        pos = end + 1;
        ++line_no;
        if (line.empty()) continue;
        const std::string where = path + ":" + std::to_string(line_no) + ": ";
        std::vector<std::string_view> cells;
        for (std::size_t a = 0;;) {
            const std::size_t b = line.find(',', a);
            cells.push_back(line.substr(a, b == std::string_view::npos ? std::string_view::npos : b - a));
            if (b == std::string_view::npos) break;
            a = b + 1;
        }
        if (cells.size() != 7)
            throw Error(where +
                        "expected 7 columns (x, y, z as numerator,denominator pairs, then the truth 0 or 1), "
                        "found " +
                        std::to_string(cells.size()));
        Eigen::Vector3d p;
        for (int k = 0; k < 3; ++k) {
            try {
                p(k) = rational_to_double(cells[2 * k], cells[2 * k + 1]);
            } catch (const Error& e) {
                throw Error(where + "column " + std::to_string(2 * k + 1) + "-" + std::to_string(2 * k + 2) + ": " +
                            e.what());
            }
        }
        const std::string_view truth = trim_blanks(cells[6]);
        if (truth != "0" && truth != "1")
            throw Error(where + "column 7: expected the truth 0 or 1, found '" + std::string(truth) + "'");
        if (row == 0) {
            current.line = line_no;
            current.collides = truth == "1";
        } else if (current.collides != (truth == "1")) {
            throw Error(where + "column 7: the truth differs from the query's first row (line " +
                        std::to_string(current.line) + ")");
        }
        current.points[static_cast<std::size_t>(row)] = p;
        if (++row == 8) {
            queries.push_back(current);
            row = 0;
        }
    }
    if (row != 0)
        throw Error(path + ":" + std::to_string(line_no) + ": the file ends within a query (" + std::to_string(row) +
                    " of its 8 rows, from line " + std::to_string(current.line) +
                    "): the rows must be a multiple of 8");
    return queries;
}

std::string double_to_rational(double x)
{
    if (!std::isfinite(x)) throw Error("not a finite number: " + std::to_string(x));
    if (x == 0) return "0,1";
    // x = mantissa · 2^exponent with an odd integer mantissa below 2^53 (frexp and ldexp are exact).
    int e = 0;
    const double f = std::frexp(std::abs(x), &e);
    auto mantissa = static_cast<std::uint64_t>(std::ldexp(f, 53));
    int exponent = e - 53;
    while ((mantissa & 1U) == 0) {
        mantissa >>= 1U;
        ++exponent;
    }
    // Decimal digits of m · 2^k, base 10^9 limbs (least significant first), doubled up to 29 bits at a time.
    const auto decimal = [](std::uint64_t m, int k) {
        constexpr std::uint64_t base = 1000000000;
        std::vector<std::uint64_t> limbs;
        for (; m != 0; m /= base)
            limbs.push_back(m % base);
        while (k > 0) {
            const int step = std::min(k, 29);
            std::uint64_t carry = 0;
            for (std::uint64_t& l : limbs) {
                const std::uint64_t v = (l << static_cast<unsigned>(step)) + carry;
                l = v % base;
                carry = v / base;
            }
            for (; carry != 0; carry /= base)
                limbs.push_back(carry % base);
            k -= step;
        }
        if (limbs.empty()) return std::string("0");
        std::string text = std::to_string(limbs.back());
        char digits[16];
        for (std::size_t i = limbs.size() - 1; i-- > 0;) {
            std::snprintf(digits, sizeof digits, "%09llu", static_cast<unsigned long long>(limbs[i]));
            text += digits;
        }
        return text;
    };
    const std::string sign = x < 0 ? "-" : "";
    if (exponent >= 0) return sign + decimal(mantissa, exponent) + ",1";
    return sign + decimal(mantissa, 0) + "," + decimal(1, -exponent);
}

void write_ccd_queries(const std::string& path, const std::vector<CcdQuery>& queries)
{
    // The text of every coordinate first: a value that is not finite is bad input, refused before any file exists.
    for (const CcdQuery& q : queries)
        for (std::size_t r = 0; r < q.points.size(); ++r)
            for (int k = 0; k < 3; ++k)
                if (!std::isfinite(q.points[r][k]))
                    throw Error(path + ": query " + std::to_string(&q - queries.data()) + ", row " + std::to_string(r) +
                                ": coordinate " + std::to_string(k) + " is not finite");
    write_atomically(path, [&](const std::string& tmp) {
        std::FILE* f = std::fopen(tmp.c_str(), "wb");
        if (!f) throw WriteError(path + ": cannot create file: " + std::strerror(errno));
        errno = 0;
        bool wrote = true;
        std::string rows;
        for (const CcdQuery& q : queries) {
            rows.clear();
            for (const Eigen::Vector3d& p : q.points) {
                for (int k = 0; k < 3; ++k)
                    rows += double_to_rational(p[k]) + ",";
                rows += q.collides ? "1\n" : "0\n";
            }
            if (std::fwrite(rows.data(), 1, rows.size(), f) != rows.size()) {
                wrote = false;
                break;
            }
        }
        const bool flushed = std::fflush(f) == 0;
        const int err = errno;
        const bool closed = std::fclose(f) == 0;
        if (!wrote || !flushed || !closed) throw WriteError(path + ": write failed: " + std::strerror(err ? err : EIO));
    });
}

std::vector<CcdQuery> read_ccd_queries(const std::string& path)
{
    return parse_ccd_queries(path, read_file(path));
}

} // namespace tethash::io
