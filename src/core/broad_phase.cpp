// The broad phases by method (broad_phase.hpp): each in its own file, chosen here.
#include "broad_phase.hpp"

#include "bp_brute_force.hpp"
#include "tethash/error.hpp"

namespace tethash::detail {

std::unique_ptr<BroadPhase> make_broad_phase(Method method)
{
    switch (method) {
    case Method::brute_force:
        return std::make_unique<BruteForce>();
    case Method::hash:
    case Method::automatic:
        break;
    default:
        throw Error(std::string("method '") + to_string(method) + "' is not built yet");
    }
    throw Error(std::string("method '") + to_string(method) + "' has no broad phase of its own");
}

} // namespace tethash::detail
