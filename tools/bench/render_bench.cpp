// tethash_render_bench: frames per second of `tethash render` on bodies of many boundary triangles (copies of a mesh
// file, or of the generator's torus, side by side, one object each), at 800x600 by default: the drawing alone
// (rasterising a frame read before) and a frame read and drawn (the .vtu read, its boundary faces from the topology,
// kept across frames). Medians of the repeats; the machine and the compiler flags printed with them.
#include "machine.hpp"
#include "tethash/io/mesh_io.hpp"
#include "tethash/io/pvd.hpp"
#include "tethash/io/vtu.hpp"
#include "tethash/meshing/generate.hpp"
#include "tethash/render/series.hpp"

#include <CLI/CLI.hpp>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

namespace {

double median(std::vector<double> v)
{
    std::sort(v.begin(), v.end());
    return v.size() % 2 ? v[v.size() / 2] : 0.5 * (v[v.size() / 2 - 1] + v[v.size() / 2]);
}

} // namespace

int main(int argc, char** argv)
{
    using namespace tethash;
    CLI::App app{"tethash_render_bench: frames per second of the software rasteriser on ~100k boundary triangles"};
    int resolution = 58, repeat = 15, width = 800, height = 600, frames = 5, copies = 2;
    std::string mesh;
    std::string dir = (std::filesystem::temp_directory_path() / "tethash_render_bench").string();
    app.add_option("--resolution", resolution, "Generator resolution of each torus")->capture_default_str();
    app.add_option("--repeat", repeat, "Draws timed (the median is printed)")->capture_default_str();
    app.add_option("--width", width)->capture_default_str();
    app.add_option("--height", height)->capture_default_str();
    app.add_option("--frames", frames, "Frames of the series written")->capture_default_str();
    app.add_option("--mesh", mesh, "A mesh file instead of the generated torus");
    app.add_option("--copies", copies, "Copies of the body side by side, each an object")->capture_default_str();
    app.add_option("--dir", dir, "Folder for the frames")->capture_default_str();
    CLI11_PARSE(app, argc, argv);

    std::printf("tethash_render_bench: %s, flags '%s'\n", TETHASH_BENCH_COMPILER, TETHASH_BENCH_FLAGS);
    std::printf("machine: %s\n", tethash::bench::machine_name().c_str());
    // Copies of one body side by side along x (each an object), falling a little from frame to frame.
    TetMesh body;
    if (mesh.empty()) {
        meshing::GenerateParams p;
        p.shape = "torus";
        p.resolution = resolution;
        body = meshing::generate(p);
    } else {
        body = io::read_tet_mesh(mesh);
    }
    body.vertex_object.clear();
    body.tet_object.clear();
    body.ensure_object_ids();
    TetMesh scene = body;
    const double step = 1.2 * (body.positions.col(0).maxCoeff() - body.positions.col(0).minCoeff());
    for (int c = 1; c < copies; ++c) {
        TetMesh copy = body;
        copy.positions.col(0).array() += step * c;
        scene.append(copy);
    }
    const Index boundary = static_cast<Index>(boundary_faces(scene.tets).rows());
    std::filesystem::create_directories(dir);
    std::vector<io::PvdEntry> entries;
    for (int f = 0; f < frames; ++f) {
        TetMesh m = scene;
        m.positions.col(2).array() -= 0.05 * f;
        const std::string name = "frame_" + std::to_string(f) + ".vtu";
        io::write_vtu((std::filesystem::path(dir) / name).string(), m);
        entries.push_back({0.1 * f, name, 0});
    }
    io::write_pvd_parts((std::filesystem::path(dir) / "scene.pvd").string(), entries);
    std::printf("scene: %d x %s, %d vertices, %d tets, %d boundary triangles; image %dx%d; %d frames\n", copies,
                mesh.empty() ? "torus" : mesh.c_str(), scene.num_vertices(), scene.num_tets(), boundary, width, height,
                frames);

    render::RenderOptions o;
    o.view.width = width;
    o.view.height = height;
    render::SeriesRenderer renderer(render::open_series(dir), o);
    const render::FrameGeometry g = renderer.load(static_cast<std::size_t>(frames - 1));
    std::vector<double> draw, load_draw;
    using clock = std::chrono::steady_clock;
    for (int r = 0; r < repeat; ++r) {
        auto t0 = clock::now();
        const render::Image im = renderer.draw(g);
        auto t1 = clock::now();
        draw.push_back(std::chrono::duration<double, std::milli>(t1 - t0).count());
        const render::Image im2 = renderer.draw(renderer.load(static_cast<std::size_t>(r % frames)));
        load_draw.push_back(std::chrono::duration<double, std::milli>(clock::now() - t1).count());
        if (im.rgb.empty() || im2.rgb.empty()) return 1;
    }
    const double d = median(draw), ld = median(load_draw);
    std::printf("draw a frame (rasterise):        median %.2f ms = %.1f frames/s (%d repeats)\n", d, 1e3 / d, repeat);
    std::printf("read and draw a frame (.vtu):    median %.2f ms = %.1f frames/s\n", ld, 1e3 / ld);
    std::filesystem::remove_all(dir);
    return 0;
}
