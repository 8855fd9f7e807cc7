#pragma once
/// \file io/ccd_queries.hpp
/// The query files of the continuous collision detection benchmark of Wang et al. (ACM TOG 40(5), 2021): CSV,
/// 8 rows per query, each row "xn,xd,yn,yd,zn,zd,truth": x, y, z as rationals (decimal numerator, signed, and
/// denominator, of any size) and the query's ground truth (1: the primitives meet for some t in [0, 1]; 0: never).
/// Vertex-face rows: v, f0, f1, f2 at t = 0, then the same at t = 1; edge-edge rows: ea0, ea1, eb0, eb1 at t = 0,
/// then at t = 1.
#include "tethash/error.hpp"

#include <Eigen/Core>

#include <array>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace tethash::io {

struct CcdQuery {
    std::array<Eigen::Vector3d, 8> points; ///< the 8 rows, each coordinate the double nearest the rational
    bool collides = false;                 ///< ground truth
    std::int64_t line = 0;                 ///< line of the query's first row (1-based)
};

/// The queries of a benchmark file. Throws Error "PATH:LINE: …" on a row without 7 columns, a cell that is not
/// an integer, a zero denominator, a truth other than 0 or 1, a truth that changes within a query, a value whose
/// magnitude does not fit a double, or a row count that is not a multiple of 8.
std::vector<CcdQuery> read_ccd_queries(const std::string& path);
/// The same on text already in memory; `path` names it in messages.
std::vector<CcdQuery> parse_ccd_queries(const std::string& path, std::string_view text);

/// The double nearest num / den (ties to even), both decimal integers of any length, num with an optional sign
/// and den positive. Throws Error (message without location) on bad digits, a zero denominator, or a result
/// whose magnitude is 2^1024 or more after rounding.
double rational_to_double(std::string_view num, std::string_view den);

/// The exact rational of a finite double as the text "num,den": num a signed decimal integer, den a power of two (1
/// for an integer), the fraction reduced; rational_to_double reads it back bit for bit (0 and −0: "0,1"). Throws
/// Error on a value that is not finite.
std::string double_to_rational(double x);

/// Writes `queries` in the format above (8 rows each, ground truth `collides`) to `path`, atomically (file.hpp:
/// nothing half-written is left). Throws Error when `path` cannot name a file (a folder, a missing folder) or a
/// coordinate is not finite, WriteError when the file system refuses it.
void write_ccd_queries(const std::string& path, const std::vector<CcdQuery>& queries);

} // namespace tethash::io
