// The broad phases by method (broad_phase.hpp): each in its own file, chosen here.
#include "broad_phase.hpp"

#include "bp_brute_force.hpp"
#include "bp_bvh.hpp"
#include "bp_hierarchical_grid.hpp"
#include "bp_octree_loose.hpp"
#include "bp_sort_sweep.hpp"
#include "bp_uniform_grid.hpp"
#include "tethash/error.hpp"

namespace tethash::detail {

std::unique_ptr<BroadPhase> make_broad_phase(Method method)
{
    switch (method) {
    case Method::brute_force:
        return std::make_unique<BruteForce>();
    case Method::uniform_grid:
        return std::make_unique<UniformGrid>();
    case Method::hierarchical_grid:
        return std::make_unique<HierarchicalGrid>();
    case Method::sort_sweep:
        return std::make_unique<SortSweep>();
    case Method::bvh:
        return std::make_unique<Bvh>(false);
    case Method::bvh_refit:
        return std::make_unique<Bvh>(true);
    case Method::octree_loose:
        return std::make_unique<LooseOctree>();
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
