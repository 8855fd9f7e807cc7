#pragma once
/// \file render/raster.hpp
/// A small software rasteriser for pictures of simulation runs: a pinhole camera, triangles filled with a z-buffer
/// (flat Lambert shading, one colour per triangle), and text in a bitmap font. No window, no GPU.
#include "tethash/mesh.hpp"

#include <Eigen/Core>

#include <cstdint>
#include <string>
#include <vector>

namespace tethash::render {

struct Rgb {
    std::uint8_t r = 0, g = 0, b = 0;
    friend bool operator==(const Rgb&, const Rgb&) = default;
};

/// An RGB image, rows from the top, 3 bytes a pixel.
struct Image {
    int width = 0, height = 0;
    std::vector<std::uint8_t> rgb; ///< width × height × 3
    Rgb at(int x, int y) const
    {
        const std::size_t i =
            3 * (static_cast<std::size_t>(y) * static_cast<std::size_t>(width) + static_cast<std::size_t>(x));
        return {rgb[i], rgb[i + 1], rgb[i + 2]};
    }
};

/// How the camera looks at the scene: angles about the scene's up axis, a zoom and the image size.
struct View {
    double azimuth = 30;   ///< degrees about the up axis (0: from −y for z up, from +z for y up, from −z for x up)
    double elevation = 20; ///< degrees above the horizontal plane, within ±89
    double zoom = 1;       ///< > 1 comes closer
    int width = 800, height = 600;
    Eigen::Vector3d up{0, 0, 1}; ///< the scene's up axis (unit)
    double fov_y = 30;           ///< vertical field of view, degrees
};

/// A pinhole camera: image x to the right, y down, pixel centres at integer + 0.5.
struct Camera {
    Eigen::Vector3d eye{0, 0, 0};
    Eigen::Vector3d forward{0, 1, 0}, right{1, 0, 0}, up{0, 0, 1}; ///< orthonormal, right = forward × up
    double focal = 1;                                              ///< pixels per unit of tangent
    int width = 800, height = 600;
    double near = 1e-3; ///< distance along forward below which geometry is clipped

    /// Image coordinates (x, y) of p and its distance along forward (≤ near: not visible).
    Eigen::Vector3d project(const Eigen::Vector3d& p) const;
};

/// The camera that sees the whole box [lo, hi] (its bounding sphere within the image) from `view`'s angles. Throws
/// Error for a size outside 16..8192, a non-finite box, an elevation beyond ±89 or a zoom ≤ 0.
Camera frame_box(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi, const View& view);

/// Draws into an image with a depth buffer.
class Canvas {
  public:
    explicit Canvas(const Camera& camera);
    void clear(Rgb background);
    /// Fills triangles t (k × 3 rows of x) with colour[k], shaded by the angle between the face and a light above
    /// the camera's left shoulder. With `outward` (one vertex per triangle, or empty): the vertex on the inner side
    /// of each triangle (the fourth corner of its tet); triangles seen from their inner side are skipped (back faces
    /// of closed bodies), which only saves time.
    void draw_triangles(const Positions& x, const Triangles& t, const std::vector<Rgb>& colour,
                        const std::vector<Index>& inner = {});
    /// Text in a 5 × 7 pixel font scaled by `scale`, its top-left corner at (x, y). Characters without a glyph are
    /// drawn as a box.
    void draw_text(int x, int y, const std::string& text, Rgb colour, int scale = 1);
    /// A filled rectangle (clipped to the image), over everything.
    void fill_rect(int x0, int y0, int x1, int y1, Rgb colour);
    /// Width in pixels of `text` drawn at `scale`.
    static int text_width(const std::string& text, int scale = 1);
    const Camera& camera() const { return m_camera; }
    const Image& image() const { return m_image; }

  private:
    void fill(const Eigen::Vector3d* p, Rgb c); // one triangle in camera space, clipped at near
    Camera m_camera;
    Image m_image;
    std::vector<float> m_depth;         ///< 1 / distance of the nearest surface so far (0: none)
    std::vector<Eigen::Vector3d> m_cam; // scratch: positions in camera space
};

} // namespace tethash::render
