// Pictures of small scenes checked against the geometry: the pixel at an object's projected centroid has its colour,
// pixels outside the projected bounds the background, two objects two colours, the nearer one where one hides the
// other (whatever the drawing order); the ground and the obstacles of a series; PNG and GIF files that decode to
// the image drawn.
#include "render_support.hpp"
#include "support.hpp"

#include "tethash/io/pvd.hpp"
#include "tethash/io/vtu.hpp"
#include "tethash/render/image_io.hpp"
#include "tethash/render/series.hpp"

#include <Eigen/Geometry>

#include <random>

using namespace tethash;
using namespace tethash::test;
using render::Rgb;

namespace {

/// Draws the frame file `vtu` alone with `options`; returns the image and the camera.
std::pair<render::Image, render::Camera> draw_file(const std::string& vtu, const render::RenderOptions& options = {})
{
    render::SeriesRenderer r(render::open_series(vtu), options);
    return {r.draw(r.load(0)), r.camera()};
}

Rgb pixel_at(const render::Image& image, const Eigen::Vector3d& p)
{
    return image.at(static_cast<int>(std::floor(p.x())), static_cast<int>(std::floor(p.y())));
}

/// The image box of the projected corners of the mesh's bounding box.
std::pair<Eigen::Vector2d, Eigen::Vector2d> projected_box(const render::Camera& cam, const TetMesh& m)
{
    const Eigen::Vector3d lo = m.positions.colwise().minCoeff().transpose(),
                          hi = m.positions.colwise().maxCoeff().transpose();
    Eigen::Vector2d a(1e30, 1e30), b(-1e30, -1e30);
    for (int c = 0; c < 8; ++c) {
        const Eigen::Vector3d p(c & 1 ? hi.x() : lo.x(), c & 2 ? hi.y() : lo.y(), c & 4 ? hi.z() : lo.z());
        const Eigen::Vector3d q = cam.project(p);
        a = a.cwiseMin(q.head<2>()), b = b.cwiseMax(q.head<2>());
    }
    return {a, b};
}

} // namespace

TEST(RenderPictures, ASingleTetHasItsColourAtItsCentroidAndBackgroundOutside)
{
    const auto dir = temp_dir();
    TetMesh m;
    m.positions.resize(4, 3);
    m.positions << 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1;
    m.tets.resize(1, 4);
    m.tets << 0, 1, 2, 3;
    io::write_vtu((dir / "tet.vtu").string(), m);
    const auto [image, cam] = draw_file((dir / "tet.vtu").string());
    ASSERT_EQ(image.width, 800);
    ASSERT_EQ(image.height, 600);
    const Rgb c = pixel_at(image, cam.project(centroid(m)));
    EXPECT_TRUE(is_shade_of(c, render::object_colour(0))) << int(c.r) << " " << int(c.g) << " " << int(c.b);
    EXPECT_NE(c, render::background_colour());
    // Outside the projected bounds (and away from the corner text): the background; a frame alone has no ground.
    const auto [a, b] = projected_box(cam, m);
    int outside = 0;
    for (int y = 40; y < image.height; y += 23)
        for (int x = 0; x < image.width; x += 17)
            if (x + 1 < a.x() || x > b.x() + 1 || y + 1 < a.y() || y > b.y() + 1) {
                ++outside;
                ASSERT_EQ(image.at(x, y), render::background_colour()) << x << "," << y;
            }
    EXPECT_GT(outside, 500);
}

TEST(RenderPictures, TwoObjectsGetTwoColoursAndTheNearerHidesTheFarther)
{
    const auto dir = temp_dir();
    // Side by side along x: each centroid shows its own object's colour.
    TetMesh two = cube_mesh({-1, 0, 0}, 1, 0);
    two.append(cube_mesh({1, 0, 0}, 1));
    ASSERT_EQ(two.tet_object.back(), 1);
    io::write_vtu((dir / "two.vtu").string(), two);
    {
        const auto [image, cam] = draw_file((dir / "two.vtu").string());
        const Rgb left = pixel_at(image, cam.project({-1, 0, 0})), right = pixel_at(image, cam.project({1, 0, 0}));
        EXPECT_TRUE(is_shade_of(left, render::object_colour(0)));
        EXPECT_TRUE(is_shade_of(right, render::object_colour(1)));
        EXPECT_NE(left, right);
        EXPECT_NE(render::object_colour(0), render::object_colour(1));
    }
    // One behind the other on the line of sight (azimuth 0, elevation 0 with z up looks along +y): the front cube
    // (y = 0) covers the back one's centroid, whichever of them is drawn first.
    render::RenderOptions front_view;
    front_view.view.azimuth = 0;
    front_view.view.elevation = 0;
    for (int order = 0; order < 2; ++order) {
        TetMesh near = cube_mesh({0, 0, 0}, 1, 0), far = cube_mesh({0, 3, 0}, 1, 0);
        TetMesh m = order == 0 ? near : far;
        m.append(order == 0 ? far : near);
        const Index near_object = order == 0 ? 0 : 1, far_object = 1 - near_object;
        io::write_vtu((dir / "line.vtu").string(), m);
        const auto [image, cam] = draw_file((dir / "line.vtu").string(), front_view);
        ASSERT_GT(cam.forward.y(), 0.99); // looking along +y
        const Rgb at_far = pixel_at(image, cam.project({0, 3, 0}));
        EXPECT_TRUE(is_shade_of(at_far, render::object_colour(near_object))) << "order " << order;
        EXPECT_FALSE(is_shade_of(at_far, render::object_colour(far_object))) << "order " << order;
        // The far cube, smaller in perspective, hides wholly behind the near one: none of its colour anywhere.
        bool far_seen = false;
        for (int y = 0; y < image.height; ++y)
            for (int x = 0; x < image.width; ++x)
                far_seen = far_seen || is_shade_of(image.at(x, y), render::object_colour(far_object));
        EXPECT_FALSE(far_seen) << "order " << order;
    }
}

TEST(RenderPictures, ASeriesDrawsItsGroundAndObstaclesAndTheFrameNearestInTime)
{
    const auto dir = temp_dir();
    // Two frames of a cube falling along z, a ground square at z = 0 (object −1) and an obstacle box beside it.
    const TetMesh a = cube_mesh({0, 0, 2}, 1), b = cube_mesh({0, 0, 0.5}, 1);
    io::write_vtu((dir / "f0.vtu").string(), a);
    io::write_vtu((dir / "f1.vtu").string(), b);
    meshing::SurfaceMesh s;
    const TetMesh box = cube_mesh({3, 0, 0.5}, 1);
    const Triangles box_faces = boundary_faces(box.tets);
    s.vertices.resize(12, 3);
    s.vertices.topRows(8) = box.positions;
    s.vertices.bottomRows(4) << -5, -5, 0, 5, -5, 0, 5, 5, 0, -5, 5, 0;
    s.triangles.resize(box_faces.rows() + 2, 3);
    s.triangles.topRows(box_faces.rows()) = box_faces;
    s.triangles.bottomRows(2) << 8, 9, 10, 8, 10, 11;
    std::vector<Index> object(static_cast<std::size_t>(box_faces.rows()), 1);
    object.push_back(-1), object.push_back(-1);
    io::write_vtu_surface((dir / "static.vtu").string(), s, object);
    io::write_pvd_parts((dir / "scene.pvd").string(),
                        {{0, "f0.vtu", 0}, {0, "static.vtu", 1}, {0.5, "f1.vtu", 0}, {0.5, "static.vtu", 1}});
    const render::Series series = render::open_series(dir.string());
    ASSERT_EQ(series.frames.size(), 2u);
    ASSERT_EQ(series.statics.size(), 1u);
    render::SeriesRenderer r(series, {});
    const render::Camera& cam = r.camera();
    const render::Image last = r.draw(r.load(1));
    EXPECT_TRUE(is_shade_of(pixel_at(last, cam.project(centroid(b))), render::object_colour(0)));
    // The obstacle in its colour; the ground below the scene in one of its tiles' greys; the cube's first place
    // (z = 2) empty at the last frame.
    EXPECT_TRUE(is_shade_of(pixel_at(last, cam.project({3, 0, 0.5})), render::obstacle_colour()));
    const Rgb ground = pixel_at(last, cam.project({-2, -2, 0}));
    EXPECT_TRUE(is_shade_of(ground, render::ground_colour(0)) || is_shade_of(ground, render::ground_colour(1)))
        << int(ground.r) << " " << int(ground.g) << " " << int(ground.b);
    EXPECT_FALSE(is_shade_of(pixel_at(last, cam.project({0, 0, 2})), render::object_colour(0)));
    // The first frame has the cube up there; the camera frames both frames (the same camera for each).
    const render::Image first = r.draw(r.load(0));
    EXPECT_TRUE(is_shade_of(pixel_at(first, cam.project(centroid(a))), render::object_colour(0)));
    // Without the ground: the background there.
    render::RenderOptions no_ground;
    no_ground.ground = false;
    render::SeriesRenderer r2(series, no_ground);
    EXPECT_EQ(pixel_at(r2.draw(r2.load(1)), r2.camera().project({-2, -2, 0})), render::background_colour());
}

TEST(RenderPictures, AFieldColoursTheBodiesAndAMissingFieldIsNamed)
{
    const auto dir = temp_dir();
    TetMesh m = cube_mesh({0, 0, 0}, 1);
    io::Fields f;
    f.point.push_back({"heat", 1, std::vector<double>(8, 0.0)});
    io::write_vtu((dir / "cold.vtu").string(), m, f);
    f.point[0].values.assign(8, 1.0);
    io::write_vtu((dir / "hot.vtu").string(), m, f);
    render::RenderOptions o;
    o.field = "heat";
    o.range = std::make_pair(0.0, 1.0);
    const auto [cold, cam] = draw_file((dir / "cold.vtu").string(), o);
    const auto [hot, cam2] = draw_file((dir / "hot.vtu").string(), o);
    const Rgb c = pixel_at(cold, cam.project({0, 0, 0})), h = pixel_at(hot, cam2.project({0, 0, 0}));
    EXPECT_TRUE(is_shade_of(c, {68, 1, 84}));    // the low end of the map: dark blue
    EXPECT_TRUE(is_shade_of(h, {253, 231, 37})); // the high end: yellow
    o.field = "pressure";
    expect_error([&] { draw_file((dir / "cold.vtu").string(), o); },
                 {"cold.vtu", "no point or cell array 'pressure'", "heat"});
}

TEST(RenderPictures, PngDecodesToTheImageDrawn)
{
    render::Image image;
    image.width = 37, image.height = 21;
    image.rgb.resize(3 * 37 * 21);
    std::mt19937 rng(5);
    for (auto& v : image.rgb)
        v = static_cast<std::uint8_t>(rng());
    const std::string png = render::encode_png(image);
    const Png decoded = decode_png(png);
    ASSERT_TRUE(decoded.ok);
    EXPECT_EQ(decoded.width, 37);
    EXPECT_EQ(decoded.height, 21);
    EXPECT_TRUE(decoded.rgb == image.rgb);
}

TEST(RenderPictures, GifHasOneImagePerFrameThatDecodesToThePalettesColours)
{
    // Noise of colours the palette holds exactly (no dithering): many LZW table resets, every code width.
    const int w = 203, h = 117;
    const std::vector<Rgb> exact = {{255, 0, 0}, {0, 255, 0}, {0, 0, 255}, {255, 255, 255}, {0, 0, 0}, {51, 85, 102}};
    std::mt19937 rng(11);
    render::GifEncoder gif(w, h);
    std::vector<render::Image> images;
    for (int f = 0; f < 3; ++f) {
        render::Image im;
        im.width = w, im.height = h;
        for (int i = 0; i < w * h; ++i) {
            // Runs of one colour and noise, so that both long and short strings go into the table.
            const Rgb c = exact[f == 1 ? (i / 50) % exact.size() : rng() % exact.size()];
            im.rgb.insert(im.rgb.end(), {c.r, c.g, c.b});
        }
        gif.add_frame(im, 4 + f);
        images.push_back(im);
    }
    const GifFile g = parse_gif(gif.finish());
    ASSERT_TRUE(g.valid) << g.error;
    EXPECT_EQ(g.width, w);
    EXPECT_EQ(g.height, h);
    ASSERT_EQ(g.images.size(), 3u);
    ASSERT_EQ(g.palette.size(), 256u);
    for (std::size_t f = 0; f < 3; ++f) {
        EXPECT_EQ(g.delays[f], static_cast<int>(4 + f));
        for (int i = 0; i < w * h; ++i) {
            const Rgb want{images[f].rgb[3 * static_cast<std::size_t>(i)],
                           images[f].rgb[3 * static_cast<std::size_t>(i) + 1],
                           images[f].rgb[3 * static_cast<std::size_t>(i) + 2]};
            ASSERT_EQ(g.palette[static_cast<std::size_t>(g.images[f][static_cast<std::size_t>(i)])], want)
                << "frame " << f << " pixel " << i;
        }
    }
}

TEST(RenderPictures, CameraAndOptionsRefuseWhatCannotBeDrawn)
{
    render::View v;
    v.width = 8;
    expect_error([&] { render::frame_box({0, 0, 0}, {1, 1, 1}, v); }, {"image size 8x600", "16 to 8192"});
    v = {};
    v.elevation = 90;
    expect_error([&] { render::frame_box({0, 0, 0}, {1, 1, 1}, v); }, {"elevation"});
    v = {};
    expect_error([&] { render::frame_box({1, 0, 0}, {0, 1, 1}, v); }, {"bounds"});
    expect_error([&] { render::open_series("/nonexistent/run"); }, {"/nonexistent/run", "no such file"});
    const auto dir = temp_dir();
    write_text(dir / "a.txt", "x");
    expect_error([&] { render::open_series((dir / "a.txt").string()); }, {"a.txt", "expected a run folder"});
    expect_error([&] { render::open_series(dir.string()); }, {"no scene.pvd"});
    expect_error([&] { render::check_render_path("x.jpg"); }, {"x.jpg", ".png, .gif or .mp4"});
}
