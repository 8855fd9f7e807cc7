#include "objects.hpp"

#include "tethash/error.hpp"
#include "tethash/io/mesh_io.hpp"
#include "tethash/io/surface.hpp"
#include "tethash/meshing/generate.hpp"
#include "tethash/meshing/tetrahedralize.hpp"

#include <Eigen/Geometry>

#include <cmath>
#include <string>

namespace tethash::sim {

namespace {

using Vec3 = Eigen::Vector3d;
using Mat3 = Eigen::Matrix3d;

/// Loads or generates the mesh of one object (one object id, no labels), transformed.
TetMesh load_object(const ObjectSpec& o)
{
    TetMesh m;
    if (!o.mesh.empty()) {
        if (io::classify_path(o.mesh) == io::PathKind::surface) {
            meshing::TetrahedralizeParams tp;
            tp.resolution = o.surface_resolution;
            m = meshing::tetrahedralize(io::read_surface(o.mesh), tp);
        } else {
            m = io::read_mesh(o.mesh);
        }
    } else if (o.generate) {
        m = meshing::generate(*o.generate);
    } else if (o.data) {
        m = *o.data;
    } else {
        throw Error("object '" + o.name + "': no mesh, generate or data");
    }
    m.check_consistency("object '" + o.name + "'");
    if (m.num_tets() == 0) throw Error("object '" + o.name + "': the mesh has no tets");
    m.vertex_object.clear();
    m.tet_object.clear();
    m.vertex_label.clear();
    m.tet_label.clear();
    transform_positions(o, m.positions);
    if (m.rest_positions.rows()) transform_positions(o, m.rest_positions);
    for (Index i = 0; i < m.num_vertices(); ++i)
        if (!m.positions.row(i).allFinite())
            throw Error("object '" + o.name + "': vertex " + std::to_string(i) + " is not finite");
    return m;
}

} // namespace

void transform_positions(const ObjectSpec& o, Positions& p)
{
    const Mat3 rot = (Eigen::AngleAxisd(o.rotate_deg.z() * M_PI / 180, Vec3::UnitZ()) *
                      Eigen::AngleAxisd(o.rotate_deg.y() * M_PI / 180, Vec3::UnitY()) *
                      Eigen::AngleAxisd(o.rotate_deg.x() * M_PI / 180, Vec3::UnitX()))
                         .toRotationMatrix();
    for (Index i = 0; i < p.rows(); ++i) {
        const Vec3 q = rot * (o.scale.cwiseProduct(p.row(i).transpose())) + o.translate;
        p.row(i) = q.transpose();
    }
}

SceneObjects load_objects(const Scene& scene)
{
    if (scene.objects.empty()) throw Error(scene.source + ": the scene has no objects");
    SceneObjects out;
    for (const ObjectSpec& o : scene.objects) {
        TetMesh m = load_object(o);
        const Index v0 = out.mesh.num_vertices(), t0 = out.mesh.num_tets();
        out.mesh.append(m);
        out.vertices.emplace_back(v0, m.num_vertices());
        out.tets.emplace_back(t0, m.num_tets());
        out.materials.push_back(o.material);
        out.is_static.push_back(o.is_static ? 1 : 0);
        ObjectOptions opt;
        opt.self_collision = o.self_collision;
        opt.is_static = o.is_static;
        out.options.push_back(opt);
    }
    out.mesh.ensure_object_ids();
    return out;
}

std::vector<std::string> apply_pins(const Scene& scene, const SceneObjects& objects, Model& model)
{
    std::vector<std::string> warnings;
    const Index n = objects.mesh.num_vertices();
    for (size_t p = 0; p < scene.pins.size(); ++p) {
        const PinRegion& pin = scene.pins[p];
        Index first = 0, count = n;
        if (pin.object >= 0) {
            if (pin.object >= static_cast<int>(objects.vertices.size()))
                throw Error("pin " + std::to_string(p) + ": object " + std::to_string(pin.object) + " does not exist");
            first = objects.vertices[static_cast<size_t>(pin.object)].first;
            count = objects.vertices[static_cast<size_t>(pin.object)].second;
        }
        for (Index id : pin.vertices) {
            if (id < 0 || id >= count)
                throw Error("pin " + std::to_string(p) + ": vertex " + std::to_string(id) + " out of range (" +
                            std::to_string(count) + " vertices)");
            model.fixed[static_cast<size_t>(first + id)] = 1;
        }
        if (pin.has_box) {
            std::int64_t hit = 0;
            for (Index i = first; i < first + count; ++i) {
                const Vec3 q = objects.mesh.positions.row(i).transpose();
                if ((q.array() >= pin.box_min.array()).all() && (q.array() <= pin.box_max.array()).all()) {
                    model.fixed[static_cast<size_t>(i)] = 1;
                    ++hit;
                }
            }
            if (hit == 0) warnings.push_back("pin " + std::to_string(p) + ": the box holds no vertex");
        }
    }
    return warnings;
}

} // namespace tethash::sim
