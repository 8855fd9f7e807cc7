#pragma once
// Subcommands of the tethash program: each tools/tethash/<name>.cpp registers itself with a static
// Registrar, so adding a command touches no other file.
#include "tethash/mesh.hpp"

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

/// Adds `--objects-from-labels[=separate|join]` (info, detect): each tet label of a file is an object.
void add_objects_from_labels_option(CLI::App& sub, std::string& value);
/// Adds `--linearize` (info, detect, convert): quadratic (10-node) tets are read as the tets of their corners.
void add_linearize_option(CLI::App& sub, bool& value);
/// Throws Error unless `value` is "", "separate" or "join".
void check_objects_from_labels_value(const std::string& value);
/// Splits `mesh` (read from `path`) into objects by its tet labels (split_objects_by_label); `value`
/// is "separate" (a vertex shared by two labels is an error) or "join". Returns a one-line note.
std::string objects_from_labels(TetMesh& mesh, const std::string& path, const std::string& value);

/// Sets the OpenMP thread count when n > 0; returns the count in effect.
int set_threads(int n);
/// True when standard error is a terminal (progress bars); plain lines otherwise.
bool stderr_is_terminal();

} // namespace tethash::cli
