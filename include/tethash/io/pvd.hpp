#pragma once
/// \file io/pvd.hpp
/// ParaView collections (.pvd): time series of mesh files.
#include "tethash/error.hpp"

#include <string>
#include <utility>
#include <vector>

namespace tethash::io {

/// One dataset of a collection: a file (relative to the .pvd) at a time, in a part. A simulation writes its frames as
/// part 0 and the static obstacles (one file, repeated at every time) as part 1.
struct PvdEntry {
    double time = 0;
    std::string file;
    int part = 0;
};

/// (time, file name relative to the .pvd) entries, all part 0.
void write_pvd(const std::string& path, const std::vector<std::pair<double, std::string>>& entries);
/// Entries with their parts (written in the order given).
void write_pvd_parts(const std::string& path, const std::vector<PvdEntry>& entries);
/// The (timestep, file) entries of a ParaView collection, in file order (every part).
std::vector<std::pair<double, std::string>> read_pvd(const std::string& path);
/// The entries with their parts (part="..." absent: 0; timestep absent: 0), in file order.
std::vector<PvdEntry> read_pvd_parts(const std::string& path);

} // namespace tethash::io
