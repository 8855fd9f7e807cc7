// The broad phases by method (broad_phase.hpp): each in its own file, chosen here.
#include "broad_phase.hpp"

#include "tethash/error.hpp"

namespace tethash::detail {

std::unique_ptr<BroadPhase> make_broad_phase(Method method)
{
    switch (method) {
    case Method::brute_force:
        return make_brute_force();
    case Method::uniform_grid:
        return make_uniform_grid();
    case Method::hierarchical_grid:
        return make_hierarchical_grid();
    case Method::sort_sweep:
        return make_sort_sweep();
    case Method::bvh:
        return make_bvh(false);
    case Method::bvh_refit:
        return make_bvh(true);
    case Method::octree_loose:
        return make_loose_octree();
    case Method::portals:
        return make_portals();
    case Method::octree:
    case Method::octree_point:
    case Method::kd_tree:
    case Method::kd_tree_point:
    case Method::bsp_tree:
    case Method::bsp_tree_balanced:
        return make_split_tree_broad_phase(method);
    case Method::hash:
    case Method::automatic:
        break;
    }
    throw Error(std::string("method '") + to_string(method) + "' has no broad phase of its own");
}

} // namespace tethash::detail
