#pragma once
/// \file error.hpp
/// Errors thrown by tethash. The library never calls exit(); the command line maps
/// `Error` (bad input: files, parameters, API arguments) to exit status 2 and
/// `RunFailure` (something went wrong while running, e.g. a simulation blew up or an output file
/// could not be written: `WriteError`) to 1.

#include <stdexcept>
#include <string>

namespace tethash {

/// Bad input. The message names what is wrong and where (file and line, key, parameter and value, element id).
class Error : public std::runtime_error {
  public:
    using std::runtime_error::runtime_error;
};

/// A failure while running on valid input (for example a simulation that diverged).
class RunFailure : public std::runtime_error {
  public:
    using std::runtime_error::runtime_error;
};

/// An output file the file system refused to take (no permission, a read-only or special file system, a full disk,
/// an I/O error), naming the file. A path that cannot name a file (a folder, a missing folder, a file where a folder
/// should be) is bad input, an `Error`. Either way nothing half-written is left.
class WriteError : public RunFailure {
  public:
    using RunFailure::RunFailure;
};

} // namespace tethash
