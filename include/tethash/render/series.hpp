#pragma once
/// \file render/series.hpp
/// Pictures of simulation runs: a run's frames (a folder written by `tethash simulate`, its scene.pvd, or one
/// frame .vtu) drawn with the rasteriser of raster.hpp to a PNG (one frame), an animated GIF or an MP4 (through
/// the ffmpeg program). The camera frames every frame's bounds, so an animation does not jump.
#include "tethash/error.hpp"
#include "tethash/render/raster.hpp"

#include <Eigen/Core>

#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace tethash::render {

/// What a run is made of, as read from its files.
struct Series {
    std::string source;                                 ///< the path given
    std::vector<std::pair<double, std::string>> frames; ///< (time, path) of the bodies' frames, in time order
    std::vector<std::string> statics;                   ///< surfaces drawn at every time (a series' other parts)
    std::optional<Eigen::Vector3d> up;                  ///< from the run's run.json, when there is one
    bool has_time = false;                              ///< the times are the simulated times (not for a lone .vtu)
};

/// Opens RUN_DIR (its scene.pvd), a .pvd or a .vtu (with its series' times and static surfaces when the folder's
/// scene.pvd lists it). Throws Error naming the path and the reason (missing, not a run, no frames, a frame file
/// missing).
Series open_series(const std::string& path);

struct RenderOptions {
    View view;             ///< angles, zoom, size; view.up is replaced unless up_given
    bool up_given = false; ///< view.up as given (else the run's, else the ground's normal, else z)
    std::string field;     ///< "": one colour per object; else a point or cell array of the frames
    std::optional<std::pair<double, double>> range; ///< the field's colour range (default: over every frame)
    bool ground = true;                             ///< draw the ground of the static surfaces
    std::optional<double> time;                     ///< a PNG: the frame nearest this time (default: the last frame)
    std::vector<double> times; ///< a PNG: the frames nearest these times side by side (a strip of panels)
    double fps = 0;            ///< an animation's frames per second (0: the run's own pace, within 5..50)
    int every = 1;             ///< an animation takes every n-th frame
};

/// The colour of object k (distinct for the first ten, then repeating).
Rgb object_colour(Index k);
/// The colours of the background, of the static obstacles and of the ground's two tiles.
Rgb background_colour();
Rgb obstacle_colour();
Rgb ground_colour(int tile);

/// Renders `series` to `out` (.png: one frame; .gif; .mp4 with ffmpeg on PATH). Checks the options and the output
/// path before drawing (Error: a bad extension, size, field or range, no ffmpeg for .mp4; WriteError: a folder
/// that takes no file); writes atomically. `progress` (may be empty) hears (frames done, frames in all).
/// Returns the frames drawn.
int render_series(const Series& series, const RenderOptions& options, const std::string& out,
                  const std::function<void(int, int)>& progress = {});

/// A frame's triangles as drawn: its boundary faces (each with the fourth corner of its tet, for back faces), their
/// object ids and field values.
struct FrameGeometry {
    double time = 0;
    Positions x;
    Triangles faces;
    std::vector<Index> inner;       ///< per face: the tet's vertex opposite it
    std::vector<Index> face_object; ///< per face: its tet's object id
    std::vector<double> face_value; ///< per face: the field (mean of its vertices, or its tet's); empty without one
};

class RendererImpl;

/// The drawing of one series with one set of options: the camera framing every frame, the ground, the static
/// surfaces and the field's range are set up once (reading every frame once); then each frame is read and drawn.
class SeriesRenderer {
  public:
    /// Throws Error for options that do not fit the series (a field no frame has, an empty range, a bad view).
    SeriesRenderer(const Series& series, const RenderOptions& options);
    ~SeriesRenderer();
    SeriesRenderer(const SeriesRenderer&) = delete;
    SeriesRenderer& operator=(const SeriesRenderer&) = delete;

    /// Reads frame k of the series (its boundary faces are computed once per topology).
    FrameGeometry load(std::size_t k);
    /// Draws a frame: background, ground, static surfaces, the bodies, the time in the top-left corner, the
    /// field's colour bar.
    Image draw(const FrameGeometry& frame);
    const Camera& camera() const;

  private:
    std::unique_ptr<RendererImpl> m_impl;
};

/// Throws Error unless `path` ends in .png, .gif or .mp4 (naming `what`).
void check_render_path(const std::string& path, const std::string& what = "output");

} // namespace tethash::render
