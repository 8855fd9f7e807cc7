#pragma once
/// \file error.hpp
/// Errors thrown by tethash. The library never calls exit(); the command line maps
/// `Error` (bad input: files, parameters, API arguments) to exit status 2 and
/// `RunFailure` (something went wrong while running, e.g. a simulation blew up) to 1.

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

} // namespace tethash
