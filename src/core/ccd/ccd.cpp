// Input checks and names of the continuous queries (include/tethash/ccd.hpp).
#include "ccd_impl.hpp"

#include "tethash/error.hpp"

#include <string>

namespace tethash::ccd {

namespace detail {

void check_query(const Points& x, const CcdParams& params, const char* what)
{
    bool ok = true;
    for (const auto& row : x)
        for (const double c : row)
            ok = ok && std::abs(c) <= kMaxMagnitude; // false for NaN and infinities
    if (!ok) {
        for (int i = 0; i < 8; ++i)
            for (int k = 0; k < 3; ++k)
                if (!(std::abs(x[i][k]) <= kMaxMagnitude))
                    throw Error(std::string(what) + ": coordinate " + std::to_string(k) + " of point " +
                                std::to_string(i) + " (" + std::to_string(x[i][k]) +
                                ") is not finite or above 1e50 in magnitude");
    }
    if (!(params.tolerance > 0 && params.tolerance < std::numeric_limits<double>::infinity()))
        throw Error(std::string(what) + ": tolerance must be positive and finite, got " +
                    std::to_string(params.tolerance));
    if (params.max_iterations < 1)
        throw Error(std::string(what) + ": max_iterations must be at least 1, got " +
                    std::to_string(params.max_iterations));
}

} // namespace detail

const char* outcome_name(CcdOutcome outcome)
{
    switch (outcome) {
    case CcdOutcome::boxes_apart:
        return "boxes_apart";
    case CcdOutcome::never_coplanar:
        return "never_coplanar";
    case CcdOutcome::excluded:
        return "excluded";
    case CcdOutcome::within_tolerance:
        return "within_tolerance";
    case CcdOutcome::iteration_cap:
        return "iteration_cap";
    }
    return "unknown";
}

} // namespace tethash::ccd
