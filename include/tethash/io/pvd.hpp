#pragma once
/// \file io/pvd.hpp
/// ParaView collections (.pvd): time series of mesh files.
#include "tethash/error.hpp"

#include <string>
#include <utility>
#include <vector>

namespace tethash::io {

/// (time, file name relative to the .pvd) entries.
void write_pvd(const std::string& path, const std::vector<std::pair<double, std::string>>& entries);
/// The (timestep, file) entries of a ParaView collection, in file order.
std::vector<std::pair<double, std::string>> read_pvd(const std::string& path);

} // namespace tethash::io
