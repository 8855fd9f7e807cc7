#pragma once
// `tethash detect --continuous FRAME0 FRAME1`: continuous detection over the step between two frames of the same
// meshes (tethash/continuous.hpp); called by detect.cpp.
#include <cstdint>
#include <string>
#include <vector>

namespace tethash::cli {

struct ContinuousOptions {
    std::string frame0, frame1;
    std::string contacts_path;       ///< .csv, or empty
    int threads = 0;                 ///< as parsed (0: every hardware thread)
    bool no_self = false;            ///< drop pairs within one object
    std::vector<int> static_objects; ///< drop pairs whose two objects are both static
    std::string objects_from_labels; ///< "", "separate" or "join"
    bool linearize = false;
};

void run_continuous(const ContinuousOptions& o);

} // namespace tethash::cli
