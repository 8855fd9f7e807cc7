#pragma once
// tethash study spheres: the options and the run of the spheres experiment (study/spheres.hpp); study.cpp
// registers them with the other studies.
#include "tethash/study/spheres.hpp"

#include <CLI/CLI.hpp>

#include <string>
#include <vector>

namespace tethash::cli {

struct SpheresArgs {
    study::SpheresOptions o;
    std::vector<CLI::Option*> options; ///< the spheres-only options (an error with another study)
};

/// Adds --spheres, --frames, --depths, --methods, --radius, --seed, --leaf-size to `sub`.
void add_spheres_options(CLI::App& sub, SpheresArgs& a);
/// Throws Error naming the first spheres-only option given to study `what` (not spheres).
void reject_spheres_options(const SpheresArgs& a, const std::string& what);
/// Runs the experiment into `out` (default "spheres"), progress on stderr unless `quiet`; prints a summary.
void run_spheres_command(SpheresArgs& a, const std::string& out, bool quiet, const std::string& command_line);

} // namespace tethash::cli
