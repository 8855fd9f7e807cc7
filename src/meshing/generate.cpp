// Shapes for `tethash generate`: signed-distance functions meshed on the BCC lattice (tetrahedralize.cpp).
#include "tethash/meshing/generate.hpp"

#include "tethash/meshing/tetrahedralize.hpp"

#include "tethash/error.hpp"

#include <algorithm>
#include <cmath>
#include <functional>

namespace tethash::meshing {

namespace {

using Vec3 = Eigen::Vector3d;

double sd_box(const Vec3& p, const Vec3& half)
{
    const Vec3 d = p.cwiseAbs() - half;
    return d.cwiseMax(0.0).norm() + std::min(d.maxCoeff(), 0.0);
}

double sd_capsule(const Vec3& p, const Vec3& a, const Vec3& b, double r)
{
    const Vec3 ab = b - a;
    const double len2 = ab.squaredNorm();
    const double t = len2 > 0 ? std::clamp((p - a).dot(ab) / len2, 0.0, 1.0) : 0.0;
    return (p - (a + t * ab)).norm() - r;
}

/// Polynomial smooth minimum: blends within distance k; never above min(a, b), at most k/4 below.
double smooth_min(double a, double b, double k)
{
    const double h = std::max(k - std::abs(a - b), 0.0) / k;
    return std::min(a, b) - h * h * k / 4.0;
}

// Bunny-like blob: body, head, two ears, tail, front paws, smoothly joined.
constexpr double kBlobBlend = 0.06;
struct Ball {
    Vec3 a, b; ///< segment ends (a == b: a sphere)
    double r;
};
const std::vector<Ball>& blob_parts()
{
    static const std::vector<Ball> parts = {
        {{0.0, 0.0, 0.0}, {0.0, 0.0, 0.0}, 0.30},           // body
        {{-0.12, 0.0, -0.03}, {-0.12, 0.0, -0.03}, 0.27},   // haunch
        {{0.30, 0.0, 0.20}, {0.30, 0.0, 0.20}, 0.17},       // head
        {{0.30, 0.07, 0.30}, {0.25, 0.11, 0.55}, 0.06},     // ear
        {{0.30, -0.07, 0.30}, {0.25, -0.11, 0.55}, 0.06},   // ear
        {{-0.38, 0.0, 0.05}, {-0.38, 0.0, 0.05}, 0.08},     // tail
        {{0.22, 0.10, -0.24}, {0.22, 0.10, -0.24}, 0.08},   // paw
        {{0.22, -0.10, -0.24}, {0.22, -0.10, -0.24}, 0.08}, // paw
    };
    return parts;
}
double sd_blob(const Vec3& p)
{
    double d = 1e30;
    for (const Ball& b : blob_parts())
        d = smooth_min(d, sd_capsule(p, b.a, b.b, b.r), kBlobBlend);
    return d;
}
std::pair<Vec3, Vec3> blob_box()
{
    Vec3 lo = Vec3::Constant(1e30), hi = Vec3::Constant(-1e30);
    for (const Ball& b : blob_parts()) {
        const double pad = b.r + kBlobBlend / 4.0;
        lo = lo.cwiseMin(b.a.cwiseMin(b.b) - Vec3::Constant(pad));
        hi = hi.cwiseMax(b.a.cwiseMax(b.b) + Vec3::Constant(pad));
    }
    return {lo, hi};
}

struct Shape {
    ShapeInfo info;
    Vec3 natural_min;                       ///< natural bounding box (scale 1)
    std::function<double(const Vec3&)> sdf; ///< in natural coordinates
};

const std::vector<Shape>& shapes()
{
    static const std::vector<Shape> all = [] {
        std::vector<Shape> s;
        auto add = [&](std::string name, std::string desc, const Vec3& lo, const Vec3& hi,
                       std::function<double(const Vec3&)> f) {
            s.push_back({{std::move(name), std::move(desc), hi - lo}, lo, std::move(f)});
        };
        add("box", "unit cube", Vec3::Constant(-0.5), Vec3::Constant(0.5),
            [](const Vec3& p) { return sd_box(p, Vec3::Constant(0.5)); });
        add("bar", "4 x 1 x 1 box along x (a beam)", Vec3(-2, -0.5, -0.5), Vec3(2, 0.5, 0.5),
            [](const Vec3& p) { return sd_box(p, Vec3(2, 0.5, 0.5)); });
        add("sphere", "ball of diameter 1", Vec3::Constant(-0.5), Vec3::Constant(0.5),
            [](const Vec3& p) { return p.norm() - 0.5; });
        add("torus", "torus in the xy plane, major radius 0.35, minor radius 0.15", Vec3(-0.5, -0.5, -0.15),
            Vec3(0.5, 0.5, 0.15), [](const Vec3& p) {
                const double q = std::hypot(p.x(), p.y()) - 0.35;
                return std::hypot(q, p.z()) - 0.15;
            });
        add("cylinder", "cylinder along z, diameter 1, height 1", Vec3::Constant(-0.5), Vec3::Constant(0.5),
            [](const Vec3& p) {
                const double dx = std::hypot(p.x(), p.y()) - 0.5, dz = std::abs(p.z()) - 0.5;
                return std::hypot(std::max(dx, 0.0), std::max(dz, 0.0)) + std::min(std::max(dx, dz), 0.0);
            });
        add("capsule", "capsule along x, length 1.5, diameter 0.5", Vec3(-0.75, -0.25, -0.25), Vec3(0.75, 0.25, 0.25),
            [](const Vec3& p) { return sd_capsule(p, Vec3(-0.5, 0, 0), Vec3(0.5, 0, 0), 0.25); });
        add("link", "chain link in the xy plane: 1.3 x 0.7, wire diameter 0.2", Vec3(-0.65, -0.35, -0.1),
            Vec3(0.65, 0.35, 0.1), [](const Vec3& p) {
                const double qx = std::max(std::abs(p.x()) - 0.3, 0.0);
                const double dc = std::hypot(qx, p.y()) - 0.25;
                return std::hypot(dc, p.z()) - 0.1;
            });
        const auto [lo, hi] = blob_box();
        add("blob", "bunny-like blob (body, head, ears, tail, paws smoothly joined)", lo, hi, sd_blob);
        return s;
    }();
    return all;
}

const Shape& find_shape(const std::string& name)
{
    for (const Shape& s : shapes())
        if (s.info.name == name) return s;
    std::string known;
    for (const Shape& s : shapes())
        known += (known.empty() ? "" : ", ") + s.info.name;
    throw Error("unknown shape '" + name + "' (known: " + known + ")");
}

} // namespace

const std::vector<ShapeInfo>& shape_catalog()
{
    static const std::vector<ShapeInfo> infos = [] {
        std::vector<ShapeInfo> v;
        for (const Shape& s : shapes())
            v.push_back(s.info);
        return v;
    }();
    return infos;
}

std::vector<std::string> generate_shapes()
{
    std::vector<std::string> names;
    for (const ShapeInfo& s : shape_catalog())
        names.push_back(s.name);
    return names;
}

Eigen::Vector3d shape_natural_size(const std::string& shape)
{
    return find_shape(shape).info.natural_size;
}

TetMesh generate(const GenerateParams& params)
{
    const Shape& shape = find_shape(params.shape);
    if (params.resolution < 1 || params.resolution > 1000)
        throw Error("resolution " + std::to_string(params.resolution) + " out of range (expected 1..1000)");
    if (!(params.scale > 0) || !std::isfinite(params.scale))
        throw Error("scale " + std::to_string(params.scale) + " must be a positive number");
    const bool natural = params.size == Vec3::Zero();
    if (!natural && !(params.size.minCoeff() > 0 && params.size.allFinite()))
        throw Error("size " + std::to_string(params.size.x()) + " " + std::to_string(params.size.y()) + " " +
                    std::to_string(params.size.z()) + " must be three positive numbers");
    const Vec3 nat = shape.info.natural_size;
    const Vec3 ext = (natural ? nat : params.size) * params.scale;
    const Vec3 nat_centre = shape.natural_min + 0.5 * nat;
    const Vec3 to_nat = nat.cwiseQuotient(ext); // natural units per output unit, per axis
    const double dist_scale = ext.cwiseQuotient(nat).minCoeff();
    std::function<double(const Vec3&)> sdf;
    std::function<Vec3(const Vec3&, const Vec3&)> project;
    if (params.shape == "box" || params.shape == "bar") {
        const Vec3 half = 0.5 * ext; // exact distance for boxes of any size
        sdf = [half](const Vec3& p) { return sd_box(p, half); };
        // Boundary vertices sit h/8 inside or 3h/8 outside a face (see make_lattice): put every
        // coordinate that close to a face onto it, so edges and corners get vertices too.
        project = [half](const Vec3& p, const Vec3& h) {
            Vec3 q = p;
            for (int a = 0; a < 3; ++a)
                if (std::abs(p[a]) > half[a] - 0.45 * h[a]) q[a] = std::copysign(half[a], p[a]);
            return q;
        };
    } else {
        sdf = [&shape, nat_centre, to_nat, dist_scale](const Vec3& p) {
            return shape.sdf(nat_centre + p.cwiseProduct(to_nat)) * dist_scale;
        };
    }
    try {
        return tetrahedralize_sdf(sdf, -0.5 * ext, 0.5 * ext, params.resolution, params.snap, project);
    } catch (const Error& e) {
        throw Error("generate " + params.shape + " at resolution " + std::to_string(params.resolution) + ": " +
                    e.what());
    }
}

} // namespace tethash::meshing
