#include "repair.hpp"

#include <algorithm>
#include <utility>

namespace tethash::meshing::detail {

void repair_nonmanifold(const std::vector<std::array<std::int64_t, 4>>& all, std::vector<char>& keep)
{
    using Face = std::array<std::int64_t, 3>;
    for (int round = 0; round < 8; ++round) {
        // Boundary faces of the kept set.
        std::vector<Face> faces;
        for (std::size_t t = 0; t < all.size(); ++t) {
            if (!keep[t]) continue;
            for (int f = 0; f < 4; ++f) {
                Face fc;
                int m = 0;
                for (int v = 0; v < 4; ++v)
                    if (v != f) fc[m++] = all[t][v];
                std::sort(fc.begin(), fc.end());
                faces.push_back(fc);
            }
        }
        std::sort(faces.begin(), faces.end());
        std::vector<Face> boundary;
        for (std::size_t i = 0; i < faces.size();) {
            std::size_t j = i;
            while (j < faces.size() && faces[j] == faces[i])
                ++j;
            if (j - i == 1) boundary.push_back(faces[i]);
            i = j;
        }
        faces.clear();
        std::vector<std::pair<std::int64_t, std::int64_t>> edges;
        for (const Face& v : boundary) {
            edges.push_back({v[0], v[1]});
            edges.push_back({v[0], v[2]});
            edges.push_back({v[1], v[2]});
        }
        std::sort(edges.begin(), edges.end());
        std::vector<std::pair<std::int64_t, std::int64_t>> bad_edges;
        for (std::size_t i = 0; i < edges.size();) {
            std::size_t j = i;
            while (j < edges.size() && edges[j] == edges[i])
                ++j;
            if (j - i > 2) bad_edges.push_back(edges[i]);
            i = j;
        }
        // Fans: per vertex, the boundary faces around it joined when they share an edge at the vertex.
        std::vector<std::pair<std::int64_t, std::size_t>> incident; // (vertex, boundary face)
        for (std::size_t f = 0; f < boundary.size(); ++f)
            for (auto v : boundary[f])
                incident.push_back({v, f});
        std::sort(incident.begin(), incident.end());
        std::vector<std::int64_t> bad_vertices;
        std::vector<int> parent;
        for (std::size_t i = 0; i < incident.size();) {
            std::size_t j = i;
            while (j < incident.size() && incident[j].first == incident[i].first)
                ++j;
            const std::int64_t v = incident[i].first;
            const std::size_t n = j - i;
            parent.resize(n);
            for (std::size_t a = 0; a < n; ++a)
                parent[a] = static_cast<int>(a);
            auto find = [&](int x) {
                while (parent[static_cast<std::size_t>(x)] != x)
                    x = parent[static_cast<std::size_t>(x)] =
                        parent[static_cast<std::size_t>(parent[static_cast<std::size_t>(x)])];
                return x;
            };
            for (std::size_t a = 0; a < n; ++a)
                for (std::size_t b = a + 1; b < n; ++b) {
                    const Face& fa = boundary[incident[i + a].second];
                    const Face& fb = boundary[incident[i + b].second];
                    bool share = false;
                    for (auto x : fa)
                        if (x != v && std::find(fb.begin(), fb.end(), x) != fb.end()) share = true;
                    if (share) parent[static_cast<std::size_t>(find(static_cast<int>(a)))] = find(static_cast<int>(b));
                }
            int fans = 0;
            for (std::size_t a = 0; a < n; ++a)
                if (find(static_cast<int>(a)) == static_cast<int>(a)) ++fans;
            if (fans > 1) bad_vertices.push_back(v);
            i = j;
        }
        if (bad_edges.empty() && bad_vertices.empty()) return;
        // Fill every lattice tet around each bad edge and each bad vertex.
        for (std::size_t t = 0; t < all.size(); ++t) {
            if (keep[t]) continue;
            const auto& q = all[t];
            for (int x = 0; x < 4 && !keep[t]; ++x) {
                if (std::binary_search(bad_vertices.begin(), bad_vertices.end(), q[x])) keep[t] = 1;
                for (int y = x + 1; y < 4 && !keep[t]; ++y) {
                    const std::pair<std::int64_t, std::int64_t> e{std::min(q[x], q[y]), std::max(q[x], q[y])};
                    if (std::binary_search(bad_edges.begin(), bad_edges.end(), e)) keep[t] = 1;
                }
            }
        }
    }
}

} // namespace tethash::meshing::detail
