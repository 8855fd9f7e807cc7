// tethash render: a picture (PNG) or an animation (GIF, MP4) of a run, drawn by the software rasteriser of
// tethash::render: headless, no display, no GPU.
#include "command.hpp"
#include "render_options.hpp"

#include "tethash/error.hpp"
#include "tethash/render/series.hpp"

#include <fmt/format.h>

#include <chrono>
#include <cstdio>
#include <memory>

namespace tethash::cli {
namespace {

struct RenderCommand {
    std::string input;
    std::string out;
    RenderFlags flags;
};

void run_render(const RenderCommand& o)
{
    const render::RenderOptions options = o.flags.options();
    render::check_render_path(o.out, "-o");
    const render::Series series = render::open_series(o.input);
    render_run(series, options, o.out);
}

Registrar reg{
    {"render", "Draw a run (its folder, scene.pvd or a frame .vtu) to a PNG, an animated GIF or an MP4",
     [](CLI::App& sub) {
         auto o = std::make_shared<RenderCommand>();
         sub.footer("A PNG shows one frame (the last unless --time), a GIF or MP4 every frame (--every n: every n-th). "
                    "The camera frames every frame of the run and turns with --azimuth and --elevation about the "
                    "run's up axis (run.json, else the ground's normal, else z). Bodies have one colour per object, "
                    "or --field's colour map; the ground and the static obstacles of the run (static.vtu) are drawn; "
                    "the simulated time is in the top-left corner. MP4 needs the ffmpeg program on PATH.");
         sub.add_option("input", o->input, "A run folder (written by tethash simulate), its scene.pvd, or a frame .vtu")
             ->required();
         sub.add_option("-o,--out", o->out, "The picture: .png, .gif or .mp4")->required();
         o->flags.add(sub);
         sub.callback([o] { run_render(*o); });
     }}};

} // namespace

void RenderFlags::add(CLI::App& sub, bool with_up)
{
    sub.add_option("--size", size, "Image size WxH in pixels")->capture_default_str();
    sub.add_option("--azimuth", azimuth, "Degrees about the up axis")->capture_default_str();
    sub.add_option("--elevation", elevation, "Degrees above the horizontal, -89..89")->capture_default_str();
    sub.add_option("--zoom", zoom, "Above 1 comes closer")->capture_default_str();
    if (with_up) sub.add_option("--up", up, "The up axis x, y, z, -x, -y or -z (default: the run's)");
    sub.add_option("--field", field,
                   "Colour the bodies by this point or cell array of the frames (contact, penetration_depth, "
                   "velocity as its length, object...)");
    sub.add_option("--range", range, "LO,HI: the field's colour range (default: over every frame)");
    sub.add_option("--time", time, "A PNG: the frame nearest this simulated time (default: the last)");
    sub.add_option("--times", times,
                   "A PNG: the frames nearest these times side by side (T1,T2,...), a strip of panels of --size")
        ->delimiter(',');
    sub.add_option("--fps", fps, "Frames per second of an animation (default: the run's pace, 5 to 50)");
    sub.add_option("--every", every, "An animation takes every n-th frame")->capture_default_str();
    sub.add_flag("--no-ground", no_ground, "Leave the ground out");
}

render::RenderOptions RenderFlags::options() const
{
    render::RenderOptions r;
    int w = 0, h = 0;
    char tail = 0;
    if (std::sscanf(size.c_str(), "%dx%d%c", &w, &h, &tail) != 2)
        throw Error("--size: expected WxH in pixels (such as 800x600), found '" + size + "'");
    r.view.width = w;
    r.view.height = h;
    r.view.azimuth = azimuth;
    r.view.elevation = elevation;
    r.view.zoom = zoom;
    if (w < 16 || h < 16 || w > 8192 || h > 8192)
        throw Error("--size " + size + ": each side must be 16 to 8192 pixels");
    if (!(elevation >= -89 && elevation <= 89))
        throw Error(fmt::format("--elevation: expected degrees within -89..89, found {}", elevation));
    if (!(zoom > 0) || !std::isfinite(zoom))
        throw Error(fmt::format("--zoom: expected a positive number, found {}", zoom));
    if (!std::isfinite(azimuth)) throw Error("--azimuth: expected a finite number of degrees");
    if (!up.empty()) {
        const bool minus = up[0] == '-';
        const std::string axis = minus ? up.substr(1) : up;
        if (axis != "x" && axis != "y" && axis != "z")
            throw Error("--up: expected x, y, z, -x, -y or -z, found '" + up + "'");
        r.view.up = Eigen::Vector3d::Zero();
        r.view.up[axis[0] - 'x'] = minus ? -1 : 1;
        r.up_given = true;
    }
    r.field = field;
    if (!range.empty()) {
        double lo = 0, hi = 0;
        if (std::sscanf(range.c_str(), "%lf,%lf%c", &lo, &hi, &tail) != 2 || !std::isfinite(lo) || !std::isfinite(hi) ||
            !(lo < hi))
            throw Error("--range: expected LO,HI with LO < HI, found '" + range + "'");
        if (field.empty()) throw Error("--range needs --field (the range of the field's colours)");
        r.range = std::make_pair(lo, hi);
    }
    if (time) {
        if (!std::isfinite(*time)) throw Error("--time: expected a number of seconds");
        r.time = *time;
    }
    for (double t : times)
        if (!std::isfinite(t)) throw Error("--times: expected numbers of seconds");
    if (time && !times.empty()) throw Error("--time and --times: one or the other");
    r.times = times;
    if (!(fps >= 0) || fps > 100) throw Error(fmt::format("--fps: expected 1 to 100 frames per second, found {}", fps));
    r.fps = fps;
    if (every < 1) throw Error(fmt::format("--every: expected a count of at least 1, found {}", every));
    r.every = every;
    r.ground = !no_ground;
    return r;
}

void render_run(const render::Series& series, const render::RenderOptions& options, const std::string& out)
{
    const auto start = std::chrono::steady_clock::now();
    const bool tty = stderr_is_terminal();
    const int frames = render::render_series(series, options, out, [&](int done, int total) {
        if (tty && total > 1) std::fprintf(stderr, "\rrendering frame %d/%d", done, total);
    });
    if (tty && frames > 1) std::fprintf(stderr, "\n");
    const double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    std::fprintf(stdout, "wrote %s: %d frame%s of %dx%d in %.2f s\n", out.c_str(), frames, frames == 1 ? "" : "s",
                 options.view.width, options.view.height, secs);
}

} // namespace tethash::cli
