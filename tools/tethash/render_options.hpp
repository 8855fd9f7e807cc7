#pragma once
// The picture options shared by `tethash render` and `tethash simulate --render`.
#include "tethash/render/series.hpp"

#include <CLI/CLI.hpp>

#include <optional>
#include <string>
#include <vector>

namespace tethash::cli {

struct RenderFlags {
    std::string size = "800x600";
    double azimuth = 30, elevation = 20, zoom = 1;
    std::string up, field, range;
    std::optional<double> time;
    std::vector<double> times;
    double fps = 0;
    int every = 1;
    bool no_ground = false;

    /// Adds --size, --azimuth, --elevation, --zoom, --up (with `with_up`: simulate has its own --up, the mesh's, and
    /// draws with the run's), --field, --range, --time, --times, --fps, --every, --no-ground.
    void add(CLI::App& sub, bool with_up = true);
    /// Checks them (Error naming the option) and returns them as render options.
    render::RenderOptions options() const;
};

/// Renders `series` to `out` and prints one line saying what was written.
void render_run(const render::Series& series, const render::RenderOptions& options, const std::string& out);

} // namespace tethash::cli
