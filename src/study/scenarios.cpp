// The five scenarios of Teschner et al. 2003, rebuilt with meshing::generate.
#include "tethash/study/scenarios.hpp"

#include "tethash/error.hpp"
#include "tethash/meshing/generate.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <map>
#include <mutex>

namespace tethash::study {

namespace {

/// splitmix64: a small portable generator, so that the scenes are the same with every standard library.
struct SplitMix {
    std::uint64_t state;
    std::uint64_t next()
    {
        std::uint64_t z = (state += 0x9e3779b97f4a7c15ULL);
        z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
        z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
        return z ^ (z >> 31);
    }
    /// Uniform in [0, 1).
    double uniform() { return static_cast<double>(next() >> 11) * (1.0 / 9007199254740992.0); }
};

struct Choice {
    std::string shape;
    int resolution = 0;
    TetMesh mesh;
};

/// The generated object (shape, resolution) whose tet and vertex counts are closest (in log ratio) to the targets.
Choice search_object(double target_tets, double target_vertices)
{
    const auto shapes = meshing::generate_shapes();
    Choice best;
    double best_err = std::numeric_limits<double>::infinity();
    for (const char* shape : {"sphere", "box", "blob"}) {
        if (std::find(shapes.begin(), shapes.end(), shape) == shapes.end()) continue;
        for (int res = 1; res <= 64; ++res) {
            meshing::GenerateParams p;
            p.shape = shape;
            p.resolution = res;
            TetMesh m = meshing::generate(p);
            if (m.num_tets() == 0) continue;
            const double err = std::abs(std::log(m.num_tets() / target_tets)) +
                               0.5 * std::abs(std::log(m.num_vertices() / target_vertices));
            const bool too_big = m.num_tets() > 3 * target_tets; // (read before m may be moved from)
            if (err < best_err) {
                best_err = err;
                best = Choice{shape, res, std::move(m)};
            }
            if (best.mesh.num_tets() > 0 && too_big) break;
        }
    }
    if (best.mesh.num_tets() == 0) throw Error("teschner scenarios: meshing::generate produced no usable shape");
    return best;
}

/// search_object, remembered per target (the search generates a few dozen meshes).
Choice choose_object(double target_tets, double target_vertices)
{
    static std::mutex mutex;
    static std::map<std::pair<double, double>, Choice> cache;
    std::lock_guard<std::mutex> lock(mutex);
    const auto key = std::make_pair(target_tets, target_vertices);
    auto it = cache.find(key);
    if (it == cache.end()) it = cache.emplace(key, search_object(target_tets, target_vertices)).first;
    return it->second;
}

} // namespace

const std::vector<ScenarioSpec>& teschner_specs()
{
    static const std::vector<ScenarioSpec> specs = {
        {"teschner1", 100, 1000, 1200, 6.0},     {"teschner2", 8, 4000, 1936, 15.0},
        {"teschner3", 20, 10000, 4840, 34.0},    {"teschner4", 2, 20514, 5898, 72.0},
        {"teschner5", 100, 50000, 24200, 174.0},
    };
    return specs;
}

Scenario teschner_scenario(int index)
{
    const auto& specs = teschner_specs();
    if (index < 0 || index >= static_cast<int>(specs.size()))
        throw Error("teschner scenario index " + std::to_string(index) + " out of range 0.." +
                    std::to_string(specs.size() - 1));
    const ScenarioSpec& spec = specs[static_cast<std::size_t>(index)];
    Choice obj =
        choose_object(static_cast<double>(spec.tets) / spec.objects, static_cast<double>(spec.vertices) / spec.objects);

    // Object size: the diagonal-ish extent of its bounding box.
    const auto [lo, hi] = bounding_box(obj.mesh.positions);
    const Eigen::Vector3d centre = 0.5 * (lo + hi);
    const double size = (hi - lo).maxCoeff();

    // Centres on a k × k × k lattice (filled in order), spacing 0.6 × size: every object overlaps its
    // lattice neighbours by about 40 % of its size; a small jitter breaks the symmetry.
    int k = 1;
    while (k * k * k < spec.objects)
        ++k;
    const double spacing = 0.6 * size;
    SplitMix rng{0x7e5c4e42ULL + static_cast<std::uint64_t>(index)};

    Scenario sc;
    sc.spec = spec;
    sc.shape = obj.shape;
    sc.resolution = obj.resolution;
    for (int o = 0; o < spec.objects; ++o) {
        const int ix = o % k, iy = (o / k) % k, iz = o / (k * k);
        Eigen::Vector3d c(ix * spacing, iy * spacing, iz * spacing);
        for (int a = 0; a < 3; ++a)
            c[a] += (rng.uniform() - 0.5) * 0.1 * size;
        // Uniform random rotation (Shoemake's method).
        const double u1 = rng.uniform(), u2 = rng.uniform() * 2 * M_PI, u3 = rng.uniform() * 2 * M_PI;
        const Eigen::Quaterniond q(std::sqrt(u1) * std::cos(u3), std::sqrt(1 - u1) * std::sin(u2),
                                   std::sqrt(1 - u1) * std::cos(u2), std::sqrt(u1) * std::sin(u3));
        const Eigen::Matrix3d r = q.normalized().toRotationMatrix();
        TetMesh copy;
        copy.tets = obj.mesh.tets;
        copy.positions.resize(obj.mesh.positions.rows(), 3);
        for (Eigen::Index v = 0; v < obj.mesh.positions.rows(); ++v) {
            const Eigen::Vector3d p = obj.mesh.positions.row(v).transpose() - centre;
            copy.positions.row(v) = (r * p + c).transpose();
        }
        if (o == 0) {
            sc.mesh = std::move(copy);
            sc.mesh.ensure_object_ids();
        } else {
            sc.mesh.append(copy);
        }
    }
    return sc;
}

std::vector<Scenario> teschner_scenarios()
{
    std::vector<Scenario> all;
    for (int i = 0; i < static_cast<int>(teschner_specs().size()); ++i)
        all.push_back(teschner_scenario(i));
    return all;
}

} // namespace tethash::study
