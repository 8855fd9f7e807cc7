#include "obstacles.hpp"

#include "objects.hpp"

#include "tethash/error.hpp"
#include "tethash/io/surface.hpp"

#include <algorithm>
#include <tuple>

namespace tethash::sim {

void SceneObstacles::add_contacts(const Positions& x, const std::vector<char>& fixed,
                                  const std::vector<Index>& vertex_object, std::vector<Contact>& contacts) const
{
    if (set.size() == 0) return;
    const std::size_t before = contacts.size();
    for (const ObstacleContact& o : set.query(x)) {
        if (fixed[static_cast<std::size_t>(o.vertex)]) continue;
        Contact c;
        c.vertex = o.vertex;
        c.vertex_object = vertex_object[static_cast<std::size_t>(o.vertex)];
        c.tet = -1;
        c.tet_object = first_object + o.obstacle;
        c.depth = o.depth;
        for (int r = 0; r < 3; ++r)
            c.direction[r] = o.direction[r];
        contacts.push_back(c);
    }
    std::inplace_merge(
        contacts.begin(), contacts.begin() + static_cast<std::ptrdiff_t>(before), contacts.end(),
        [](const Contact& a, const Contact& b) { return std::tie(a.vertex, a.tet) < std::tie(b.vertex, b.tet); });
}

double SceneObstacles::exact_depth(const Positions& x, const Contact& c) const
{
    return set[c.tet_object - first_object].distance(x.row(c.vertex).transpose());
}

SceneObstacles take_obstacles(Scene& scene)
{
    SceneObstacles out;
    if (std::none_of(scene.objects.begin(), scene.objects.end(),
                     [](const ObjectSpec& o) { return o.collider == Collider::bsp; }))
        return out;
    std::vector<ObjectSpec> kept;
    std::vector<int> new_index(scene.objects.size(), -1);
    for (std::size_t k = 0; k < scene.objects.size(); ++k) {
        ObjectSpec& o = scene.objects[k];
        if (o.collider != Collider::bsp) {
            new_index[k] = static_cast<int>(kept.size());
            kept.push_back(std::move(o));
            continue;
        }
        io::SurfaceMesh surface = io::read_surface(o.mesh);
        transform_positions(o, surface.vertices);
        out.set.add(Bsp(surface.vertices, surface.triangles, "object '" + o.name + "' (" + o.mesh + ")"));
        out.names.push_back(o.name);
        out.surfaces.push_back(std::move(surface));
    }
    for (std::size_t p = 0; p < scene.pins.size(); ++p) {
        PinRegion& pin = scene.pins[p];
        if (pin.object < 0 || pin.object >= static_cast<int>(new_index.size())) continue;
        if (new_index[static_cast<std::size_t>(pin.object)] < 0)
            throw Error("pin " + std::to_string(p) + ": object " + std::to_string(pin.object) +
                        " is a collider = \"bsp\" obstacle (static, nothing to pin)");
        pin.object = new_index[static_cast<std::size_t>(pin.object)];
    }
    scene.objects = std::move(kept);
    out.first_object = static_cast<Index>(scene.objects.size());
    return out;
}

} // namespace tethash::sim
