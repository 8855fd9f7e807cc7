// tethash_obstacle_bench SCENE [--collider tets|bsp] [--object K] [--every N]: runs a scene whose object K is a
// static closed surface, kept either as a BSP tree (collider = "bsp") or tetrahedralized (collider = "tets"), and
// compares the contacts against that object with the exact answer of its polyhedron: vertices inside it missed or
// reported outside it, depth error against the exact distance to the surface, time per step, memory. One collider
// per run, so that the peak memory (ru_maxrss) is the collider's.
#include "tethash/bsp.hpp"
#include "tethash/error.hpp"
#include "tethash/io/surface.hpp"
#include "tethash/sim/simulation.hpp"

#include <CLI/CLI.hpp>
#include <Eigen/Geometry>
#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <sys/resource.h>
#include <vector>

using namespace tethash;

int main(int argc, char** argv)
{
    CLI::App app{"Static obstacle as a BSP tree or as tets: contacts against the exact polyhedron, time, memory"};
    std::string scene_path, collider = "bsp";
    int object = 0, every = 10;
    app.add_option("scene", scene_path, "Scene file (TOML) whose object K is a static surface")->required();
    app.add_option("--collider", collider, "bsp or tets")->capture_default_str();
    app.add_option("--object", object, "Index of the obstacle among the scene's objects")->capture_default_str();
    app.add_option("--every", every, "Compare every N steps")->capture_default_str();
    CLI11_PARSE(app, argc, argv);
    try {
        sim::Scene scene = sim::load_scene(scene_path);
        if (object < 0 || object >= static_cast<int>(scene.objects.size()))
            throw Error("--object " + std::to_string(object) + " out of range");
        sim::ObjectSpec& o = scene.objects[static_cast<std::size_t>(object)];
        if (collider != "bsp" && collider != "tets") throw Error("--collider: bsp or tets, got " + collider);
        o.collider = collider == "bsp" ? sim::Collider::bsp : sim::Collider::tets;
        scene.output.every = 0;

        // The exact polyhedron, placed like the object.
        io::SurfaceMesh surface = io::read_surface(o.mesh);
        const Eigen::Matrix3d rot = (Eigen::AngleAxisd(o.rotate_deg.z() * M_PI / 180, Eigen::Vector3d::UnitZ()) *
                                     Eigen::AngleAxisd(o.rotate_deg.y() * M_PI / 180, Eigen::Vector3d::UnitY()) *
                                     Eigen::AngleAxisd(o.rotate_deg.x() * M_PI / 180, Eigen::Vector3d::UnitX()))
                                        .toRotationMatrix();
        for (Index i = 0; i < surface.vertices.rows(); ++i)
            surface.vertices.row(i) =
                (rot * o.scale.cwiseProduct(surface.vertices.row(i).transpose()) + o.translate).transpose();
        const Bsp truth(surface.vertices, surface.triangles, o.mesh);

        const auto t_setup = std::chrono::steady_clock::now();
        sim::Simulation s(scene);
        const double setup_ms =
            std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t_setup).count();
        // The obstacle's contacts: tet −1 (bsp) or a tet of object K (tets, K keeps its index).
        const bool bsp = collider == "bsp";
        Index first = 0, count = 0;
        std::int64_t obstacle_bytes = 0;
        if (bsp) {
            obstacle_bytes = truth.stats().bytes;
        } else {
            std::tie(first, count) = s.object_vertices(object);
            const Index tets = s.object_tets(object).second;
            obstacle_bytes = static_cast<std::int64_t>(count) * 24 + static_cast<std::int64_t>(tets) * 16;
            fmt::print("tetrahedralized obstacle: {} vertices, {} tets (surface_resolution {})\n", count, tets,
                       o.surface_resolution);
        }
        auto against_obstacle = [&](const Contact& c) { return bsp ? c.tet < 0 : c.tet_object == object; };

        std::int64_t checks = 0, inside = 0, missed = 0, outside = 0, valued = 0, contacts = 0;
        double err_sum = 0, err_max = 0, ms_steps = 0, ms_collide = 0;
        std::vector<char> reported;
        for (int step = 0; step < scene.steps; ++step) {
            const auto t0 = std::chrono::steady_clock::now();
            s.step();
            ms_steps += std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
            ms_collide += s.last_stats().ms_detect + s.last_stats().ms_depth;
            if ((step + 1) % every) continue;
            s.refresh_contacts(); // contacts at the current positions
            const Positions& x = s.positions();
            reported.assign(static_cast<std::size_t>(x.rows()), 0);
            std::vector<double> depth(static_cast<std::size_t>(x.rows()), 0.0);
            for (const Contact& c : s.contacts())
                if (against_obstacle(c)) {
                    ++contacts;
                    reported[static_cast<std::size_t>(c.vertex)] = 1;
                    depth[static_cast<std::size_t>(c.vertex)] = c.depth;
                }
            for (Index v = 0; v < x.rows(); ++v) {
                if (!bsp && v >= first && v < first + count) continue; // the obstacle's own vertices
                const bool in = truth.contains(x.row(v).transpose());
                const bool rep = reported[static_cast<std::size_t>(v)] != 0;
                ++checks;
                inside += in;
                missed += in && !rep;
                outside += rep && !in;
                if (in && rep && std::isfinite(depth[static_cast<std::size_t>(v)])) {
                    const double e =
                        std::abs(depth[static_cast<std::size_t>(v)] - truth.distance(x.row(v).transpose()));
                    err_sum += e;
                    err_max = std::max(err_max, e);
                    ++valued;
                }
            }
        }
        rusage ru{};
        getrusage(RUSAGE_SELF, &ru);
        fmt::print("scene {}, obstacle '{}' as {}: {} steps, {} comparisons (every {} steps)\n", scene_path, o.name,
                   collider, scene.steps, scene.steps / every, every);
        fmt::print("set-up {:.1f} ms; {:.3f} ms per step, of which detection + depth {:.3f} ms\n", setup_ms,
                   ms_steps / scene.steps, ms_collide / scene.steps);
        fmt::print("vertices inside the polyhedron: {} (of {} checked); contacts against it: {}; missed {}, "
                   "reported outside it {}\n",
                   inside, checks, contacts, missed, outside);
        fmt::print("depth error against the exact distance to the surface: mean {:.3g}, max {:.3g} ({} values)\n",
                   valued ? err_sum / static_cast<double>(valued) : 0.0, err_max, valued);
        fmt::print("obstacle memory: {} bytes ({}); peak RSS {} kB\n", obstacle_bytes,
                   bsp ? "tree, faces, triangle tree" : "positions and tets", ru.ru_maxrss);
    } catch (const std::exception& e) {
        fmt::print(stderr, "tethash_obstacle_bench: error: {}\n", e.what());
        return 2;
    }
    return 0;
}
