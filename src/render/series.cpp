// Pictures of runs (render/series.hpp): the frames of a series read, framed by one camera and drawn; a PNG, a GIF
// or an MP4 (frames piped to the ffmpeg program) written atomically.
#include "tethash/render/series.hpp"

#include "tethash/io/file.hpp"
#include "tethash/io/pvd.hpp"
#include "tethash/io/vtu.hpp"
#include "tethash/render/image_io.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <array>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <limits>
#include <map>
#include <set>
#include <sys/wait.h>
#include <unistd.h>

namespace tethash::render {

namespace fs = std::filesystem;

namespace {

/// The "up": [x, y, z] member of a run.json, when it has one that reads.
std::optional<Eigen::Vector3d> read_run_up(const fs::path& run_json)
{
    std::error_code ec;
    if (!fs::is_regular_file(run_json, ec)) return std::nullopt;
    std::string text;
    try {
        text = io::read_file(run_json.string());
    } catch (const Error&) {
        return std::nullopt;
    }
    const auto key = text.find("\"up\"");
    if (key == std::string::npos) return std::nullopt;
    const auto open = text.find('[', key);
    if (open == std::string::npos) return std::nullopt;
    Eigen::Vector3d up;
    const char* p = text.c_str() + open + 1;
    for (int k = 0; k < 3; ++k) {
        char* endp = nullptr;
        up[k] = std::strtod(p, &endp);
        if (endp == p) return std::nullopt;
        p = endp;
        while (*p == ' ' || *p == ',' || *p == '\n')
            ++p;
    }
    if (!up.allFinite() || up.norm() == 0) return std::nullopt;
    return up.normalized();
}

Series from_pvd(const std::string& pvd, const std::string& source)
{
    Series s;
    s.source = source;
    s.has_time = true;
    const fs::path dir = fs::path(pvd).parent_path();
    std::set<std::string> statics;
    for (const io::PvdEntry& e : io::read_pvd_parts(pvd)) {
        const std::string file = (dir / e.file).string();
        std::error_code ec;
        if (!fs::is_regular_file(file, ec))
            throw Error(pvd + ": its file '" + e.file + "' (time " + std::to_string(e.time) + ") does not exist");
        if (e.part == 0)
            s.frames.emplace_back(e.time, file);
        else if (statics.insert(file).second)
            s.statics.push_back(file);
    }
    if (s.frames.empty()) throw Error(pvd + ": lists no frames (no dataset of part 0)");
    std::stable_sort(s.frames.begin(), s.frames.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
    s.up = read_run_up(dir / "run.json");
    return s;
}

/// Boundary faces of `tets` with the tet's opposite vertex and the tet: faces of exactly one tet.
void boundary_with_tets(const Tets& tets, Triangles& faces, std::vector<Index>& inner, std::vector<Index>& tet_of)
{
    struct Face {
        std::array<Index, 3> key;
        Index tet;
        int opposite;
    };
    static constexpr int corner[4][3] = {{1, 2, 3}, {0, 3, 2}, {0, 1, 3}, {0, 2, 1}};
    std::vector<Face> all;
    all.reserve(4 * static_cast<std::size_t>(tets.rows()));
    for (Index t = 0; t < static_cast<Index>(tets.rows()); ++t)
        for (int k = 0; k < 4; ++k) {
            std::array<Index, 3> key{tets(t, corner[k][0]), tets(t, corner[k][1]), tets(t, corner[k][2])};
            std::sort(key.begin(), key.end());
            all.push_back({key, t, k});
        }
    std::sort(all.begin(), all.end(), [](const Face& a, const Face& b) { return a.key < b.key; });
    std::vector<std::size_t> kept;
    for (std::size_t i = 0; i < all.size();) {
        std::size_t j = i + 1;
        while (j < all.size() && all[j].key == all[i].key)
            ++j;
        if (j - i == 1) kept.push_back(i);
        i = j;
    }
    faces.resize(static_cast<Eigen::Index>(kept.size()), 3);
    inner.resize(kept.size());
    tet_of.resize(kept.size());
    for (std::size_t f = 0; f < kept.size(); ++f) {
        const Face& face = all[kept[f]];
        for (int c = 0; c < 3; ++c)
            faces(static_cast<Eigen::Index>(f), c) = tets(face.tet, corner[face.opposite][c]);
        inner[f] = tets(face.tet, face.opposite);
        tet_of[f] = face.tet;
    }
}

/// A field's value per point or per cell: the array's values, vectors as their length.
std::vector<double> scalar_values(const io::Field& f)
{
    const std::size_t n = f.values.size() / static_cast<std::size_t>(f.components);
    std::vector<double> out(n);
    for (std::size_t i = 0; i < n; ++i) {
        double s = 0;
        for (int c = 0; c < f.components; ++c)
            s += f.values[i * static_cast<std::size_t>(f.components) + static_cast<std::size_t>(c)] *
                 f.values[i * static_cast<std::size_t>(f.components) + static_cast<std::size_t>(c)];
        out[i] = f.components == 1 ? f.values[i] : std::sqrt(s);
    }
    return out;
}

Rgb field_colour(double u)
{
    // A perceptually ordered map from dark blue through green to yellow (five stops, linear between them).
    static constexpr double stops[5][3] = {{68, 1, 84}, {59, 82, 139}, {33, 145, 140}, {94, 201, 98}, {253, 231, 37}};
    if (!std::isfinite(u)) u = 0;
    u = std::clamp(u, 0.0, 1.0) * 4;
    const int k = std::min(3, static_cast<int>(u));
    const double w = u - k;
    const auto mix = [&](int c) {
        return static_cast<std::uint8_t>(std::lround((1 - w) * stops[k][c] + w * stops[k + 1][c]));
    };
    return {mix(0), mix(1), mix(2)};
}

/// A round step near `x`: 1, 2 or 5 times a power of ten.
double nice_step(double x)
{
    const double p = std::pow(10.0, std::floor(std::log10(x)));
    const double m = x / p;
    return (m < 1.5 ? 1 : m < 3.5 ? 2 : m < 7.5 ? 5 : 10) * p;
}

std::string short_number(double v)
{
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.3g", v);
    return buf;
}

} // namespace

Series open_series(const std::string& path)
{
    std::error_code ec;
    if (!fs::exists(path, ec)) throw Error(path + ": no such file or folder");
    if (fs::is_directory(path, ec)) {
        const fs::path pvd = fs::path(path) / "scene.pvd";
        if (!fs::is_regular_file(pvd, ec))
            throw Error(path + ": no scene.pvd in this folder (a folder written by tethash simulate has one)");
        return from_pvd(pvd.string(), path);
    }
    const std::string ext = io::extension_of(path);
    if (ext == ".pvd") return from_pvd(path, path);
    if (ext != ".vtu")
        throw Error(path + ": expected a run folder, a .pvd series or a .vtu frame, found a " +
                    (ext.empty() ? std::string("file without extension") : ext + " file"));
    Series s;
    s.source = path;
    s.frames.emplace_back(0.0, path);
    // A frame of a run: its time and the run's static surfaces from the folder's scene.pvd, when it lists the frame.
    const fs::path dir = fs::path(path).parent_path();
    const fs::path pvd = dir / "scene.pvd";
    if (fs::is_regular_file(pvd, ec)) {
        try {
            const Series run = from_pvd(pvd.string(), pvd.string());
            for (const auto& [t, f] : run.frames)
                if (fs::equivalent(f, path, ec)) {
                    s.frames[0].first = t;
                    s.has_time = true;
                    s.statics = run.statics;
                    s.up = run.up;
                    break;
                }
        } catch (const Error&) {
            // A scene.pvd that does not read leaves the frame alone.
        }
    }
    return s;
}

Rgb object_colour(Index k)
{
    static constexpr Rgb palette[10] = {{70, 130, 200},  {230, 130, 40}, {80, 170, 90},   {210, 70, 70},
                                        {150, 100, 200}, {160, 110, 70}, {220, 120, 180}, {170, 170, 50},
                                        {60, 180, 200},  {120, 120, 120}};
    return palette[static_cast<std::size_t>(std::max<Index>(k, 0) % 10)];
}
Rgb background_colour()
{
    return {236, 240, 245};
}
Rgb obstacle_colour()
{
    return {205, 195, 175};
}
Rgb ground_colour(int tile)
{
    return tile % 2 ? Rgb{150, 152, 150} : Rgb{175, 177, 175};
}

namespace {
std::string find_ffmpeg();
} // namespace

void check_render_path(const std::string& path, const std::string& what)
{
    const std::string ext = io::extension_of(path);
    if (ext != ".png" && ext != ".gif" && ext != ".mp4")
        throw Error(what + " '" + path + "': expected a .png, .gif or .mp4 file name, found " +
                    (ext.empty() ? std::string("no extension") : "'" + ext + "'"));
    if (ext == ".mp4" && find_ffmpeg().empty())
        throw Error(what + " '" + path +
                    "': writing .mp4 needs the ffmpeg program, not found on PATH (Debian: "
                    "apt-get install ffmpeg); a .gif needs nothing");
}

// ---- SeriesRenderer -------------------------------------------------------------------------------------------

class RendererImpl {
  public:
    RendererImpl(const Series& series, const RenderOptions& options);
    FrameGeometry load(std::size_t k);
    Image draw(const FrameGeometry& frame);

    Series series;
    RenderOptions options;
    Camera camera;
    Positions static_x, ground_x;
    Triangles static_t, ground_t;
    std::vector<Rgb> static_colour, ground_colour_of;
    double lo_value = 0, hi_value = 1;
    // The boundary of the last topology read.
    Tets last_tets;
    Triangles faces;
    std::vector<Index> inner, tet_of;

  private:
    FrameGeometry read(std::size_t k, bool need_values);
};

FrameGeometry RendererImpl::read(std::size_t k, bool need_values)
{
    const auto& [time, path] = series.frames[k];
    io::VtuContents c = io::read_vtu_contents(path);
    FrameGeometry g;
    g.time = time;
    if (c.mesh.num_tets() == 0) throw Error(path + ": the frame has no tets to draw");
    if (c.mesh.tets.rows() != last_tets.rows() || c.mesh.tets != last_tets) {
        boundary_with_tets(c.mesh.tets, faces, inner, tet_of);
        last_tets = c.mesh.tets;
    }
    g.faces = faces;
    g.inner = inner;
    g.face_object.resize(tet_of.size());
    for (std::size_t f = 0; f < tet_of.size(); ++f)
        g.face_object[f] = c.mesh.tet_object.empty() ? 0 : c.mesh.tet_object[static_cast<std::size_t>(tet_of[f])];
    if (need_values && !options.field.empty()) {
        const io::Field* field = nullptr;
        bool cell = false;
        for (const io::Field& f : c.fields.point)
            if (f.name == options.field) field = &f;
        if (!field)
            for (const io::Field& f : c.fields.cell)
                if (f.name == options.field) field = &f, cell = true;
        if (!field) {
            std::string names;
            for (const auto* list : {&c.fields.point, &c.fields.cell})
                for (const io::Field& f : *list)
                    names += (names.empty() ? "" : ", ") + f.name;
            throw Error(path + ": no point or cell array '" + options.field + "' to colour by (the frame has " +
                        (names.empty() ? std::string("none") : names) + ")");
        }
        const std::vector<double> v = scalar_values(*field);
        g.face_value.resize(tet_of.size());
        for (std::size_t f = 0; f < tet_of.size(); ++f) {
            if (cell) {
                g.face_value[f] = v[static_cast<std::size_t>(c.tet_cells[static_cast<std::size_t>(tet_of[f])])];
            } else {
                double sum = 0;
                for (int j = 0; j < 3; ++j)
                    sum += v[static_cast<std::size_t>(g.faces(static_cast<Eigen::Index>(f), j))];
                g.face_value[f] = sum / 3;
            }
        }
    }
    g.x = std::move(c.mesh.positions);
    return g;
}

RendererImpl::RendererImpl(const Series& s, const RenderOptions& o) : series(s), options(o)
{
    if (series.frames.empty()) throw Error(series.source + ": no frames to draw");
    if (options.every < 1) throw Error("every: expected a count of at least 1, found " + std::to_string(options.every));
    if (options.range && !(options.range->first < options.range->second))
        throw Error("range: expected LO < HI, found " + short_number(options.range->first) + "," +
                    short_number(options.range->second));
    // The bounds of every frame (and of the obstacles: not of the ground, which has no end), and the field's range.
    Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
    double vmin = std::numeric_limits<double>::infinity(), vmax = -vmin;
    for (std::size_t k = 0; k < series.frames.size(); ++k) {
        const FrameGeometry g = read(k, !options.range.has_value());
        for (Index i = 0; i < static_cast<Index>(g.x.rows()); ++i) {
            lo = lo.cwiseMin(g.x.row(i).transpose());
            hi = hi.cwiseMax(g.x.row(i).transpose());
        }
        for (double v : g.face_value)
            if (std::isfinite(v)) vmin = std::min(vmin, v), vmax = std::max(vmax, v);
    }
    if (!options.field.empty()) {
        if (options.range) {
            lo_value = options.range->first, hi_value = options.range->second;
        } else if (vmin <= vmax) {
            lo_value = vmin, hi_value = vmax > vmin ? vmax : vmin + 1;
        }
    }
    // Static surfaces: obstacles (object ≥ 0) and the ground (object −1, a plane).
    std::optional<Eigen::Vector3d> ground_normal;
    double ground_height = 0;
    std::vector<Eigen::Vector3d> sx;
    std::vector<std::array<Index, 3>> st;
    for (const std::string& path : series.statics) {
        const io::VtuContents c = io::read_vtu_contents(path);
        std::vector<double> object(static_cast<std::size_t>(c.triangles.rows()), 0.0);
        for (const io::Field& f : c.fields.cell)
            if (f.name == "object" && f.components == 1)
                for (std::size_t t = 0; t < object.size(); ++t)
                    object[t] = f.values[static_cast<std::size_t>(c.triangle_cells[t])];
        const Index base = static_cast<Index>(sx.size());
        for (Index i = 0; i < static_cast<Index>(c.mesh.positions.rows()); ++i)
            sx.emplace_back(c.mesh.positions.row(i).transpose());
        for (std::size_t t = 0; t < object.size(); ++t) {
            const auto tri = c.triangles.row(static_cast<Eigen::Index>(t));
            if (object[t] < 0) {
                const Eigen::Vector3d a = c.mesh.positions.row(tri(0)).transpose(),
                                      b = c.mesh.positions.row(tri(1)).transpose(),
                                      d = c.mesh.positions.row(tri(2)).transpose();
                const Eigen::Vector3d n = (b - a).cross(d - a);
                if (!ground_normal && n.norm() > 0) {
                    ground_normal = n.normalized();
                    ground_height = ground_normal->dot(a);
                }
                continue;
            }
            st.push_back({base + tri(0), base + tri(1), base + tri(2)});
            for (int j = 0; j < 3; ++j) {
                lo = lo.cwiseMin(c.mesh.positions.row(tri(j)).transpose());
                hi = hi.cwiseMax(c.mesh.positions.row(tri(j)).transpose());
            }
        }
    }
    static_x.resize(static_cast<Eigen::Index>(sx.size()), 3);
    for (std::size_t i = 0; i < sx.size(); ++i)
        static_x.row(static_cast<Eigen::Index>(i)) = sx[i].transpose();
    static_t.resize(static_cast<Eigen::Index>(st.size()), 3);
    for (std::size_t t = 0; t < st.size(); ++t)
        static_t.row(static_cast<Eigen::Index>(t)) << st[t][0], st[t][1], st[t][2];
    static_colour.assign(st.size(), obstacle_colour());

    View view = options.view;
    if (!options.up_given) view.up = series.up ? *series.up : ground_normal ? *ground_normal : Eigen::Vector3d(0, 0, 1);
    camera = frame_box(lo, hi, view);

    // The ground: square tiles of a round size, aligned to multiples of it, around the scene's foot.
    if (ground_normal && options.ground) {
        const Eigen::Vector3d n = *ground_normal;
        const Eigen::Vector3d centre = 0.5 * (lo + hi);
        const double radius = std::max(0.5 * (hi - lo).norm(), 1e-6);
        Eigen::Index least = 0;
        n.cwiseAbs().minCoeff(&least);
        const Eigen::Vector3d e1 = n.cross(Eigen::Vector3d::Unit(least)).normalized(), e2 = n.cross(e1);
        const double tile = nice_step(radius / 2);
        const double half = 4 * radius;
        const double u0 = std::floor((centre.dot(e1) - half) / tile), v0 = std::floor((centre.dot(e2) - half) / tile);
        const int count = std::min(80, static_cast<int>(std::ceil(2 * half / tile)) + 1);
        const Eigen::Vector3d origin = ground_height * n;
        ground_x.resize(4 * count * count, 3);
        ground_t.resize(2 * count * count, 3);
        ground_colour_of.clear();
        Index v = 0, t = 0;
        for (int i = 0; i < count; ++i)
            for (int j = 0; j < count; ++j) {
                const double u = (u0 + i) * tile, w = (v0 + j) * tile;
                ground_x.row(v) = (origin + u * e1 + w * e2).transpose();
                ground_x.row(v + 1) = (origin + (u + tile) * e1 + w * e2).transpose();
                ground_x.row(v + 2) = (origin + (u + tile) * e1 + (w + tile) * e2).transpose();
                ground_x.row(v + 3) = (origin + u * e1 + (w + tile) * e2).transpose();
                ground_t.row(t++) << v, v + 1, v + 2;
                ground_t.row(t++) << v, v + 2, v + 3;
                const int parity = (static_cast<int>(u0) + i + static_cast<int>(v0) + j) & 1;
                ground_colour_of.push_back(ground_colour(parity));
                ground_colour_of.push_back(ground_colour(parity));
                v += 4;
            }
    }
}

FrameGeometry RendererImpl::load(std::size_t k)
{
    if (k >= series.frames.size())
        throw Error("frame " + std::to_string(k) + " of a series of " + std::to_string(series.frames.size()));
    return read(k, true);
}

Image RendererImpl::draw(const FrameGeometry& frame)
{
    Canvas canvas(camera);
    canvas.clear(background_colour());
    if (ground_t.rows() > 0) canvas.draw_triangles(ground_x, ground_t, ground_colour_of);
    if (static_t.rows() > 0) canvas.draw_triangles(static_x, static_t, static_colour);
    std::vector<Rgb> colour(frame.face_object.size());
    const bool by_field = !options.field.empty() && frame.face_value.size() == colour.size();
    for (std::size_t f = 0; f < colour.size(); ++f)
        colour[f] = by_field ? field_colour((frame.face_value[f] - lo_value) / (hi_value - lo_value))
                             : object_colour(frame.face_object[f]);
    canvas.draw_triangles(frame.x, frame.faces, colour, frame.inner);
    const int scale = std::max(1, (camera.height + 200) / 300);
    const Rgb ink{30, 30, 30};
    if (series.has_time) {
        char buf[64];
        std::snprintf(buf, sizeof buf, "t = %.3f s", frame.time);
        canvas.draw_text(6 * scale, 6 * scale, buf, ink, scale);
    }
    if (!options.field.empty()) {
        // The colour bar in the bottom-left corner: the field's name, its low and high ends.
        const int bar_w = std::min(camera.width / 3, 100 * scale), bar_h = 6 * scale;
        const int x0 = 6 * scale, y0 = camera.height - 6 * scale - bar_h;
        for (int i = 0; i < bar_w; ++i)
            canvas.fill_rect(x0 + i, y0, x0 + i + 1, y0 + bar_h, field_colour(static_cast<double>(i) / (bar_w - 1)));
        canvas.draw_text(x0, y0 - 9 * scale, options.field, ink, scale);
        canvas.draw_text(x0 + bar_w + 4 * scale, y0 - scale, short_number(lo_value) + " .. " + short_number(hi_value),
                         ink, scale);
    }
    return canvas.image();
}

SeriesRenderer::SeriesRenderer(const Series& series, const RenderOptions& options)
    : m_impl(std::make_unique<RendererImpl>(series, options))
{
}
SeriesRenderer::~SeriesRenderer() = default;
FrameGeometry SeriesRenderer::load(std::size_t k)
{
    return m_impl->load(k);
}
Image SeriesRenderer::draw(const FrameGeometry& frame)
{
    return m_impl->draw(frame);
}
const Camera& SeriesRenderer::camera() const
{
    return m_impl->camera;
}

// ---- output -----------------------------------------------------------------------------------------------------

namespace {

/// The ffmpeg program on PATH, or "".
std::string find_ffmpeg()
{
    const char* path = std::getenv("PATH");
    if (!path) return {};
    std::string dirs = path;
    std::size_t start = 0;
    while (start <= dirs.size()) {
        const std::size_t end = std::min(dirs.find(':', start), dirs.size());
        const std::string dir = dirs.substr(start, end - start);
        if (!dir.empty()) {
            std::string exe = dir + "/ffmpeg";
            if (access(exe.c_str(), X_OK) == 0) return exe;
        }
        start = end + 1;
    }
    return {};
}

std::string shell_quote(const std::string& s)
{
    std::string q = "'";
    for (char c : s)
        q += c == '\'' ? std::string("'\\''") : std::string(1, c);
    return q + "'";
}

} // namespace

int render_series(const Series& series, const RenderOptions& options, const std::string& out,
                  const std::function<void(int, int)>& progress)
{
    check_render_path(out, "-o");
    const std::string ext = io::extension_of(out);
    if (!options.times.empty() && (ext != ".png" || options.times.size() > 64))
        throw Error("--times: a strip of at most 64 panels, for a .png only");
    const std::string ffmpeg = ext == ".mp4" ? find_ffmpeg() : std::string();
    if (ext == ".mp4") {
        if (options.view.width % 2 || options.view.height % 2)
            throw Error("-o '" + out + "': an .mp4 needs an even width and height, found " +
                        std::to_string(options.view.width) + "x" + std::to_string(options.view.height));
    }
    io::check_output_file(out, "-o");
    SeriesRenderer renderer(series, options);
    const std::size_t n = series.frames.size();

    if (ext == ".png") {
        const auto nearest = [&](double t) {
            std::size_t k = 0;
            double best = std::numeric_limits<double>::infinity();
            for (std::size_t i = 0; i < n; ++i)
                if (std::abs(series.frames[i].first - t) < best) best = std::abs(series.frames[i].first - t), k = i;
            return k;
        };
        std::vector<std::size_t> panels;
        for (double t : options.times)
            panels.push_back(nearest(t));
        if (panels.empty()) panels.push_back(options.time ? nearest(*options.time) : n - 1);
        // The panels side by side, left to right in the order given.
        const int w = options.view.width, h = options.view.height;
        Image strip;
        strip.width = w * static_cast<int>(panels.size());
        strip.height = h;
        strip.rgb.resize(3 * static_cast<std::size_t>(strip.width) * static_cast<std::size_t>(h));
        for (std::size_t p = 0; p < panels.size(); ++p) {
            const Image image = renderer.draw(renderer.load(panels[p]));
            for (int y = 0; y < h; ++y)
                std::copy_n(image.rgb.begin() + 3 * static_cast<std::ptrdiff_t>(y) * w, 3 * w,
                            strip.rgb.begin() + 3 * (static_cast<std::ptrdiff_t>(y) * strip.width +
                                                     static_cast<std::ptrdiff_t>(p) * w));
            if (progress) progress(static_cast<int>(p + 1), static_cast<int>(panels.size()));
        }
        write_png(out, strip);
        return static_cast<int>(panels.size());
    }

    std::vector<std::size_t> picked;
    for (std::size_t k = 0; k < n; k += static_cast<std::size_t>(options.every))
        picked.push_back(k);
    double fps = options.fps;
    if (!(fps > 0)) {
        fps = 25;
        if (series.has_time && picked.size() > 1) {
            const double span = series.frames[picked.back()].first - series.frames[picked.front()].first;
            if (span > 0) fps = std::clamp(static_cast<double>(picked.size() - 1) / span, 5.0, 50.0);
        }
    }
    const int total = static_cast<int>(picked.size());
    if (ext == ".gif") {
        GifEncoder gif(options.view.width, options.view.height);
        const int delay = static_cast<int>(std::lround(100 / fps));
        for (std::size_t i = 0; i < picked.size(); ++i) {
            gif.add_frame(renderer.draw(renderer.load(picked[i])), delay);
            if (progress) progress(static_cast<int>(i + 1), total);
        }
        io::write_text_file(out, gif.finish());
        return total;
    }
    // .mp4: raw RGB frames piped to ffmpeg, which writes the temporary file that write_atomically renames.
    io::write_atomically(out, [&](const std::string& tmp) {
        char rate[32];
        std::snprintf(rate, sizeof rate, "%.6g", fps);
        const std::string cmd = shell_quote(ffmpeg) +
                                " -hide_banner -loglevel error -y -f rawvideo -pix_fmt rgb24 -s " +
                                std::to_string(options.view.width) + "x" + std::to_string(options.view.height) +
                                " -r " + rate + " -i - -an -vcodec libx264 -pix_fmt yuv420p -f mp4 " + shell_quote(tmp);
        // A pipe that ffmpeg closed early is a failed write, not the end of this process.
        struct IgnorePipe {
            void (*old)(int) = std::signal(SIGPIPE, SIG_IGN);
            ~IgnorePipe() { std::signal(SIGPIPE, old); }
        } ignore_pipe;
        FILE* pipe = popen(cmd.c_str(), "w");
        if (!pipe) throw WriteError(out + ": cannot start ffmpeg");
        bool ok = true;
        try {
            for (std::size_t i = 0; i < picked.size() && ok; ++i) {
                const Image image = renderer.draw(renderer.load(picked[i]));
                ok = std::fwrite(image.rgb.data(), 1, image.rgb.size(), pipe) == image.rgb.size();
                if (progress) progress(static_cast<int>(i + 1), total);
            }
        } catch (...) {
            pclose(pipe);
            throw;
        }
        const int status = pclose(pipe);
        if (!ok || status == -1 || !WIFEXITED(status) || WEXITSTATUS(status) != 0)
            throw WriteError(out + ": ffmpeg failed (its messages above)");
    });
    return total;
}

} // namespace tethash::render
