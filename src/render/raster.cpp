// The rasteriser of render/raster.hpp: camera framing, triangles with a depth buffer, flat Lambert shading.
#include "tethash/render/raster.hpp"

#include "tethash/error.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <numbers>

namespace tethash::render {

Eigen::Vector3d Camera::project(const Eigen::Vector3d& p) const
{
    const Eigen::Vector3d d = p - eye;
    const double z = d.dot(forward);
    if (z <= near) return {0, 0, z};
    return {0.5 * width + focal * d.dot(right) / z, 0.5 * height - focal * d.dot(up) / z, z};
}

Camera frame_box(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi, const View& view)
{
    if (view.width < 16 || view.height < 16 || view.width > 8192 || view.height > 8192)
        throw Error("image size " + std::to_string(view.width) + "x" + std::to_string(view.height) +
                    ": each side must be 16 to 8192 pixels");
    if (!(std::abs(view.elevation) <= 89))
        throw Error("elevation " + std::to_string(view.elevation) + ": expected degrees within -89..89");
    if (!(view.zoom > 0) || !std::isfinite(view.zoom))
        throw Error("zoom " + std::to_string(view.zoom) + ": expected a positive number");
    if (!std::isfinite(view.azimuth)) throw Error("azimuth: expected a finite number of degrees");
    if (!lo.allFinite() || !hi.allFinite() || (lo.array() > hi.array()).any())
        throw Error("the scene's bounds are empty or not finite: nothing to frame");
    const Eigen::Vector3d up = view.up.normalized();
    // The reference direction towards the camera at azimuth 0, per up axis: −y for z up, +z for y up, −z for x up
    // (so that the other axis runs to the right); for another up vector, the axis least along it, made orthogonal.
    Eigen::Index a = 0;
    up.cwiseAbs().maxCoeff(&a);
    Eigen::Vector3d ref = a == 2   ? Eigen::Vector3d(0, -1, 0)
                          : a == 1 ? Eigen::Vector3d(0, 0, 1)
                                   : Eigen::Vector3d(0, 0, -1);
    ref = (ref - ref.dot(up) * up).normalized();
    const Eigen::Vector3d side = up.cross(ref);
    const double az = view.azimuth * std::numbers::pi / 180, el = view.elevation * std::numbers::pi / 180;
    const Eigen::Vector3d towards =
        std::cos(el) * (std::cos(az) * ref + std::sin(az) * side) + std::sin(el) * up; // from the target to the eye
    const Eigen::Vector3d centre = 0.5 * (lo + hi);
    const double radius = std::max(0.5 * (hi - lo).norm(), 1e-9 * std::max(1.0, centre.norm()));
    Camera c;
    c.width = view.width;
    c.height = view.height;
    const double half_y = 0.5 * view.fov_y * std::numbers::pi / 180;
    c.focal = 0.5 * view.height / std::tan(half_y);
    // The half angle that the narrower side of the image covers; the bounding sphere fills 90 % of it.
    const double half = std::atan(0.5 * std::min(view.width, view.height) / c.focal);
    const double distance = radius / std::sin(0.9 * half) / view.zoom;
    c.eye = centre + distance * towards;
    c.forward = -towards;
    c.right = c.forward.cross(up).normalized();
    c.up = c.right.cross(c.forward);
    c.near = 1e-3 * distance;
    return c;
}

Canvas::Canvas(const Camera& camera) : m_camera(camera)
{
    m_image.width = camera.width;
    m_image.height = camera.height;
    const std::size_t n = static_cast<std::size_t>(camera.width) * static_cast<std::size_t>(camera.height);
    m_image.rgb.assign(3 * n, 0);
    m_depth.assign(n, 0.0f);
}

void Canvas::clear(Rgb background)
{
    for (std::size_t i = 0; i < m_depth.size(); ++i) {
        m_image.rgb[3 * i] = background.r;
        m_image.rgb[3 * i + 1] = background.g;
        m_image.rgb[3 * i + 2] = background.b;
    }
    std::fill(m_depth.begin(), m_depth.end(), 0.0f);
}

void Canvas::fill(const Eigen::Vector3d* p, Rgb c)
{
    const double near = m_camera.near;
    // Clip the triangle at z = near (Sutherland-Hodgman against one plane): up to 4 corners.
    Eigen::Vector3d poly[4];
    int k = 0;
    for (int i = 0; i < 3; ++i) {
        const Eigen::Vector3d& a = p[i];
        const Eigen::Vector3d& b = p[(i + 1) % 3];
        const bool ain = a.z() > near, bin = b.z() > near;
        if (ain) poly[k++] = a;
        if (ain != bin) poly[k++] = a + (b - a) * ((near - a.z()) / (b.z() - a.z()));
    }
    const int w = m_camera.width, h = m_camera.height;
    const double f = m_camera.focal, cx = 0.5 * w, cy = 0.5 * h;
    for (int t = 1; t + 1 < k; ++t) {
        const Eigen::Vector3d* q[3] = {&poly[0], &poly[t], &poly[t + 1]};
        double sx[3], sy[3], iz[3];
        for (int i = 0; i < 3; ++i) {
            iz[i] = 1.0 / q[i]->z();
            sx[i] = cx + f * q[i]->x() * iz[i];
            sy[i] = cy - f * q[i]->y() * iz[i];
        }
        const double area = (sx[1] - sx[0]) * (sy[2] - sy[0]) - (sx[2] - sx[0]) * (sy[1] - sy[0]);
        if (!(std::abs(area) > 1e-12)) continue;
        // The pixel box, clamped in floating point first: a corner just past the near plane projects far out.
        const auto pixel = [](double v, int size) { return static_cast<int>(std::clamp(v, -1.0, double(size))); };
        const int x0 = std::max(0, pixel(std::floor(std::min({sx[0], sx[1], sx[2]}) - 0.5), w));
        const int x1 = std::min(w - 1, pixel(std::ceil(std::max({sx[0], sx[1], sx[2]}) - 0.5), w));
        const int y0 = std::max(0, pixel(std::floor(std::min({sy[0], sy[1], sy[2]}) - 0.5), h));
        const int y1 = std::min(h - 1, pixel(std::ceil(std::max({sy[0], sy[1], sy[2]}) - 0.5), h));
        if (x0 > x1 || y0 > y1) continue;
        const double inv = 1.0 / area;
        // Edge functions e_i(x, y) = A_i x + B_i y + C_i, the barycentric weight of corner i times the area.
        double A[3], B[3], C[3];
        for (int i = 0; i < 3; ++i) {
            const int j = (i + 1) % 3, l = (i + 2) % 3;
            A[i] = (sy[j] - sy[l]) * inv;
            B[i] = (sx[l] - sx[j]) * inv;
            C[i] = (sx[j] * sy[l] - sx[l] * sy[j]) * inv;
        }
        // Depth 1/z is affine in the image: dz/dx, dz/dy.
        const double zx = A[0] * iz[0] + A[1] * iz[1] + A[2] * iz[2];
        const double zy = B[0] * iz[0] + B[1] * iz[1] + B[2] * iz[2];
        const double zc = C[0] * iz[0] + C[1] * iz[1] + C[2] * iz[2];
        for (int y = y0; y <= y1; ++y) {
            const double py = y + 0.5;
            double e0 = A[0] * (x0 + 0.5) + B[0] * py + C[0];
            double e1 = A[1] * (x0 + 0.5) + B[1] * py + C[1];
            double e2 = A[2] * (x0 + 0.5) + B[2] * py + C[2];
            double z = zx * (x0 + 0.5) + zy * py + zc;
            const std::size_t row = static_cast<std::size_t>(y) * static_cast<std::size_t>(w);
            for (int x = x0; x <= x1; ++x, e0 += A[0], e1 += A[1], e2 += A[2], z += zx) {
                if (e0 < 0 || e1 < 0 || e2 < 0) continue;
                const std::size_t i = row + static_cast<std::size_t>(x);
                const float zf = static_cast<float>(z);
                if (zf <= m_depth[i]) continue;
                m_depth[i] = zf;
                m_image.rgb[3 * i] = c.r;
                m_image.rgb[3 * i + 1] = c.g;
                m_image.rgb[3 * i + 2] = c.b;
            }
        }
    }
}

void Canvas::draw_triangles(const Positions& x, const Triangles& t, const std::vector<Rgb>& colour,
                            const std::vector<Index>& inner)
{
    if (colour.size() != static_cast<std::size_t>(t.rows()))
        throw Error("draw_triangles: " + std::to_string(colour.size()) + " colours for " + std::to_string(t.rows()) +
                    " triangles");
    const Camera& cam = m_camera;
    const Index n = static_cast<Index>(x.rows());
    m_cam.resize(static_cast<std::size_t>(n));
    for (Index i = 0; i < n; ++i) {
        const Eigen::Vector3d d = x.row(i).transpose() - cam.eye;
        m_cam[static_cast<std::size_t>(i)] = {d.dot(cam.right), d.dot(cam.up), d.dot(cam.forward)};
    }
    // The light: from above the camera's left shoulder.
    const Eigen::Vector3d light = (-0.35 * cam.right + 0.55 * cam.up - 0.76 * cam.forward).normalized();
    const bool cull = inner.size() == static_cast<std::size_t>(t.rows());
    for (Index k = 0; k < static_cast<Index>(t.rows()); ++k) {
        const Index a = t(k, 0), b = t(k, 1), c = t(k, 2);
        const Eigen::Vector3d pa = x.row(a).transpose(), pb = x.row(b).transpose(), pc = x.row(c).transpose();
        Eigen::Vector3d normal = (pb - pa).cross(pc - pa);
        if (cull) {
            // Outward: away from the tet's fourth corner. Seen from inside: hidden behind the body's front faces.
            if (normal.dot(x.row(inner[static_cast<std::size_t>(k)]).transpose() - pa) > 0) normal = -normal;
            if (normal.dot(cam.eye - pa) <= 0) continue;
        }
        const double len = normal.norm();
        const double lambert = len > 0 ? std::abs(normal.dot(light)) / len : 1.0;
        const double s = 0.35 + 0.65 * lambert;
        const Rgb base = colour[static_cast<std::size_t>(k)];
        const Rgb shaded{static_cast<std::uint8_t>(std::lround(base.r * s)),
                         static_cast<std::uint8_t>(std::lround(base.g * s)),
                         static_cast<std::uint8_t>(std::lround(base.b * s))};
        const Eigen::Vector3d p[3] = {m_cam[static_cast<std::size_t>(a)], m_cam[static_cast<std::size_t>(b)],
                                      m_cam[static_cast<std::size_t>(c)]};
        if (p[0].z() <= cam.near && p[1].z() <= cam.near && p[2].z() <= cam.near) continue;
        fill(p, shaded);
    }
}

void Canvas::fill_rect(int x0, int y0, int x1, int y1, Rgb colour)
{
    x0 = std::max(x0, 0), y0 = std::max(y0, 0);
    x1 = std::min(x1, m_image.width), y1 = std::min(y1, m_image.height);
    for (int y = y0; y < y1; ++y)
        for (int x = x0; x < x1; ++x) {
            const std::size_t i = 3 * (static_cast<std::size_t>(y) * static_cast<std::size_t>(m_image.width) +
                                       static_cast<std::size_t>(x));
            m_image.rgb[i] = colour.r;
            m_image.rgb[i + 1] = colour.g;
            m_image.rgb[i + 2] = colour.b;
        }
}

} // namespace tethash::render
