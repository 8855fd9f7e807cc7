#pragma once
// Subcommands of the tethash program: each tools/tethash/<name>.cpp registers itself with a static
// Registrar, so adding a command touches no other file.
#include <CLI/CLI.hpp>

#include <functional>
#include <string>
#include <vector>

namespace tethash::cli {

struct Command {
    std::string name;
    std::string description;
    /// Adds options to `sub` and sets its callback.
    std::function<void(CLI::App& sub)> setup;
};

std::vector<Command>& registry();

struct Registrar {
    explicit Registrar(Command c) { registry().push_back(std::move(c)); }
};

/// Sets the OpenMP thread count when n > 0; returns the count in effect.
int set_threads(int n);
/// True when standard error is a terminal (progress bars); plain lines otherwise.
bool stderr_is_terminal();

} // namespace tethash::cli
