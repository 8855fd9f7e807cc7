// Embeds the detector the way an FEM code would: its own xyz and tet arrays, mapped without copies.
#include <tethash/detect.hpp>
#include <tethash/oracle.hpp>

#include <cstdio>
#include <vector>

int main()
{
    // Two unit tets; vertex 7 (of the second) lies inside the first.
    std::vector<double> xyz = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 5, 5, 5, 6, 5, 5, 5, 6, 5, 0.1, 0.1, 0.1};
    std::vector<tethash::Index> tets = {0, 1, 2, 3, 4, 5, 6, 7};
    const Eigen::Map<const tethash::Positions> positions(xyz.data(), 8, 3);
    const Eigen::Map<const tethash::Tets> topology(tets.data(), 2, 4);
    std::vector<tethash::Index> vertex_object = {0, 0, 0, 0, 1, 1, 1, 1}, tet_object = {0, 1};
    tethash::Detector det;
    det.set_topology(topology, 8, vertex_object, tet_object);
    const auto& contacts = det.detect(positions);
    for (const tethash::Contact& c : contacts)
        std::printf("contact vertex %d tet %d\n", c.vertex, c.tet);
    // The installed oracle: what an embedding code tests its use of the detector against.
    const std::vector<tethash::Contact> oracle =
        tethash::brute_force_contacts(positions, topology, vertex_object, tet_object);
    const bool same = oracle.size() == contacts.size() && oracle.size() == 1 &&
                      oracle[0].vertex == contacts[0].vertex && oracle[0].tet == contacts[0].tet;
    return same && contacts[0].vertex == 7 && contacts[0].tet == 0 ? 0 : 1;
}
