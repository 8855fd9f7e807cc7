// Per-rank collision detection over MPI, the way a domain-decomposed FEM code would run it:
//  1. rank 0 holds the mesh (read from a file, or two generated bodies in contact), partitions the tets by
//     recursive coordinate bisection of their centroids (vertices by the region holding them), and sends each
//     rank what it owns;
//  2. every rank sends its neighbours the owned vertices within the ghost width (largest tet extent + skin) of
//     their regions, once; each step only the positions of those vertices travel;
//  3. every rank detects on its local mesh and keeps the contacts whose tet it owns (tethash::detect_owned);
//  4. rank 0 gathers the contacts and checks that their union is the serial detection, each contact once.
// Exit status 0 when every step agrees (a mesh without contacts is said to have none), 1 when one does not, 2 on bad
// input.
//
//   mpirun -np 4 mpi_detect [--mesh FILE] [--steps N]
#include "tethash/detect.hpp"
#include "tethash/error.hpp"
#include "tethash/io/mesh_io.hpp"
#include "tethash/meshing/generate.hpp"
#include "tethash/subdomain.hpp"

#include <mpi.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <utility>
#include <vector>

namespace {

using tethash::Index;

const char* const usage_text =
    "usage: mpirun -np RANKS mpi_detect [--mesh FILE] [--steps N]\n"
    "Per-rank collision detection: rank 0 partitions the mesh (FILE, or a box and a sphere in contact), every rank\n"
    "detects on its part and a ghost layer, and the union of the ranks' contacts is compared with the serial\n"
    "detection at each of N steps (default 3; the second object moves a little towards the first).\n"
    "Exit status: 0 when every step agrees, 1 when one does not, 2 on bad input.\n";

template <typename T> MPI_Datatype mpi_type();
template <> MPI_Datatype mpi_type<int>()
{
    return MPI_INT;
}
template <> MPI_Datatype mpi_type<double>()
{
    return MPI_DOUBLE;
}

/// Rank 0 gives rank r `per_rank[r]` (other ranks pass an empty vector of vectors).
template <typename T> std::vector<T> scatter(const std::vector<std::vector<T>>& per_rank, int rank, int size)
{
    std::vector<int> counts(static_cast<std::size_t>(size)), displs(static_cast<std::size_t>(size));
    std::vector<T> flat;
    if (rank == 0)
        for (int r = 0; r < size; ++r) {
            counts[r] = static_cast<int>(per_rank[r].size());
            displs[r] = static_cast<int>(flat.size());
            flat.insert(flat.end(), per_rank[r].begin(), per_rank[r].end());
        }
    int mine = 0;
    MPI_Scatter(counts.data(), 1, MPI_INT, &mine, 1, MPI_INT, 0, MPI_COMM_WORLD);
    std::vector<T> out(static_cast<std::size_t>(mine));
    MPI_Scatterv(flat.data(), counts.data(), displs.data(), mpi_type<T>(), out.data(), mine, mpi_type<T>(), 0,
                 MPI_COMM_WORLD);
    return out;
}

/// Every rank sends send[q] to rank q; returns what it received, concatenated in rank order.
template <typename T> std::vector<T> all_to_all(const std::vector<std::vector<T>>& send, int size)
{
    std::vector<int> scount(static_cast<std::size_t>(size)), sdispl(static_cast<std::size_t>(size)),
        rcount(static_cast<std::size_t>(size)), rdispl(static_cast<std::size_t>(size));
    std::vector<T> flat;
    for (int q = 0; q < size; ++q) {
        scount[q] = static_cast<int>(send[q].size());
        sdispl[q] = static_cast<int>(flat.size());
        flat.insert(flat.end(), send[q].begin(), send[q].end());
    }
    MPI_Alltoall(scount.data(), 1, MPI_INT, rcount.data(), 1, MPI_INT, MPI_COMM_WORLD);
    int total = 0;
    for (int q = 0; q < size; ++q) {
        rdispl[q] = total;
        total += rcount[q];
    }
    std::vector<T> out(static_cast<std::size_t>(total));
    MPI_Alltoallv(flat.data(), scount.data(), sdispl.data(), mpi_type<T>(), out.data(), rcount.data(), rdispl.data(),
                  mpi_type<T>(), MPI_COMM_WORLD);
    return out;
}

/// The default scene: a box and a sphere overlapping (objects 0 and 1).
tethash::TetMesh default_mesh()
{
    tethash::meshing::GenerateParams box;
    box.shape = "box";
    box.resolution = 7;
    tethash::meshing::GenerateParams ball;
    ball.shape = "sphere";
    ball.resolution = 9;
    tethash::TetMesh mesh = tethash::meshing::generate(box);
    tethash::TetMesh sphere = tethash::meshing::generate(ball);
    for (Eigen::Index v = 0; v < sphere.positions.rows(); ++v)
        sphere.positions.row(v) += Eigen::RowVector3d(0.55, 0.13, 0.07);
    mesh.ensure_object_ids();
    mesh.append(sphere);
    return mesh;
}

/// Positions at `step`: object 1 moves towards object 0 by `speed` per step along -x.
Eigen::RowVector3d position_at(const Eigen::RowVector3d& rest, Index object, int step, double speed)
{
    return object == 1 ? Eigen::RowVector3d(rest + Eigen::RowVector3d(-speed * step, 0, 0)) : rest;
}

std::vector<std::pair<Index, Index>> pairs_of(const std::vector<tethash::Contact>& contacts)
{
    std::vector<std::pair<Index, Index>> p;
    p.reserve(contacts.size());
    for (const auto& c : contacts)
        p.emplace_back(c.vertex, c.tet);
    return p;
}

/// Rank 0's work before any exchange: the mesh, the partition and what each rank owns.
struct Partition {
    tethash::TetMesh mesh;
    std::vector<std::vector<int>> vertex_ids, vertex_object, tet_ids, tet_corners, tet_object; ///< per rank
    std::vector<std::vector<double>> positions;                                                ///< per rank
    std::vector<double> setup; ///< the regions (lo, hi per rank), the ghost width and the speed, broadcast
};

/// On rank 0: reads (or makes) the mesh and partitions it by recursive coordinate bisection of the tet centroids
/// (`out`'s lists sized for `size` ranks). Throws tethash::Error on a bad mesh.
void partition_mesh(const std::string& mesh_path, int size, int steps, Partition& out)
{
    tethash::TetMesh& mesh = out.mesh;
    mesh = mesh_path.empty() ? default_mesh() : tethash::io::read_tet_mesh(mesh_path);
    mesh.ensure_object_ids();
    const tethash::Positions centroids = tethash::tet_centroids(mesh.positions, mesh.tets);
    const auto regions = tethash::bisect_regions(centroids, size);
    const double skin = 0.3 * tethash::mean_edge_length(mesh.positions, mesh.tets);
    const double width = tethash::ghost_width(mesh.positions, mesh.tets, skin);
    for (Index v = 0; v < mesh.num_vertices(); ++v) {
        const int r = tethash::region_of(regions, mesh.positions.row(v).transpose());
        out.vertex_ids[r].push_back(v);
        out.vertex_object[r].push_back(mesh.vertex_object[v]);
        for (int a = 0; a < 3; ++a)
            out.positions[r].push_back(mesh.positions(v, a));
    }
    for (Index t = 0; t < mesh.num_tets(); ++t) {
        const int r = tethash::region_of(regions, centroids.row(t).transpose());
        out.tet_ids[r].push_back(t);
        out.tet_object[r].push_back(mesh.tet_object[t]);
        for (int k = 0; k < 4; ++k)
            out.tet_corners[r].push_back(mesh.tets(t, k));
    }
    for (int r = 0; r < size; ++r)
        for (int a = 0; a < 3; ++a) {
            out.setup[6 * r + a] = regions[r].lo[a];
            out.setup[6 * r + 3 + a] = regions[r].hi[a];
        }
    out.setup[6 * size] = width;
    // Motion below skin / 2 over the whole run: the ghost lists stay valid without a new exchange.
    out.setup[6 * size + 1] = 0.45 * skin / steps;
    std::printf("mpi_detect: %d ranks, %d vertices, %d tets, ghost width %.4g (largest tet extent %.4g + "
                "skin %.4g)\n",
                size, mesh.num_vertices(), mesh.num_tets(), width, width - skin, skin);
}

/// What one rank owns (scattered from rank 0), and the regions, ghost width and speed every rank knows.
struct Owned {
    std::vector<int> vertex_ids, vertex_object, tet_ids, tet_corners, tet_object;
    std::vector<double> rest;
    std::vector<tethash::Region> regions;
    double width = 0, speed = 0;

    Eigen::RowVector3d rest_of(std::size_t i) const
    {
        return Eigen::RowVector3d(rest[3 * i], rest[3 * i + 1], rest[3 * i + 2]);
    }
};

Owned scatter_partition(const Partition& p, int rank, int size)
{
    Owned o;
    o.regions.resize(static_cast<std::size_t>(size));
    for (int r = 0; r < size; ++r)
        for (int a = 0; a < 3; ++a) {
            o.regions[r].lo[a] = p.setup[6 * r + a];
            o.regions[r].hi[a] = p.setup[6 * r + 3 + a];
        }
    o.width = p.setup[6 * size];
    o.speed = p.setup[6 * size + 1];
    o.vertex_ids = scatter(p.vertex_ids, rank, size);
    o.vertex_object = scatter(p.vertex_object, rank, size);
    o.rest = scatter(p.positions, rank, size);
    o.tet_ids = scatter(p.tet_ids, rank, size);
    o.tet_corners = scatter(p.tet_corners, rank, size);
    o.tet_object = scatter(p.tet_object, rank, size);
    return o;
}

/// A rank's local mesh: its subdomain, where each local vertex comes from, and what it sends to the other ranks.
struct Local {
    tethash::Subdomain sub;
    std::vector<std::pair<int, int>> order;  ///< (global id, source: i >= 0 owned index, -1 - g ghost index g)
    std::vector<std::vector<int>> send_list; ///< per rank: the owned vertices it needs as ghosts
    std::size_t ghosts = 0;
    int missing = 0; ///< tet corners outside the ghost layer (the width rule would be wrong)
};

/// Ghost lists: owned vertices within the ghost width of another rank's region, sent once with ids and objects
/// (positions travel along the same lists every step); the local mesh: owned and ghost vertices in ascending
/// global order, owned tets in local numbering.
Local build_local(const Owned& o, int rank, int size)
{
    Local l;
    const std::size_t owned = o.vertex_ids.size();
    l.send_list.assign(static_cast<std::size_t>(size), {});
    std::vector<std::vector<int>> send_ids(static_cast<std::size_t>(size)),
        send_objects(static_cast<std::size_t>(size));
    for (int q = 0; q < size; ++q) {
        if (q == rank) continue;
        for (std::size_t i = 0; i < owned; ++i)
            if (o.regions[q].distance(o.rest_of(i).transpose()) <= o.width) {
                l.send_list[q].push_back(static_cast<int>(i));
                send_ids[q].push_back(o.vertex_ids[i]);
                send_objects[q].push_back(o.vertex_object[i]);
            }
    }
    const std::vector<int> ghost_ids = all_to_all(send_ids, size);
    const std::vector<int> ghost_objects = all_to_all(send_objects, size);
    l.ghosts = ghost_ids.size();
    tethash::Subdomain& sub = l.sub;
    for (std::size_t i = 0; i < owned; ++i)
        l.order.emplace_back(o.vertex_ids[i], static_cast<int>(i));
    for (std::size_t g = 0; g < ghost_ids.size(); ++g)
        l.order.emplace_back(ghost_ids[g], -1 - static_cast<int>(g));
    std::sort(l.order.begin(), l.order.end());
    for (const auto& [id, source] : l.order) {
        sub.vertices.push_back(id);
        sub.vertex_owned.push_back(source >= 0 ? 1 : 0);
        sub.vertex_object.push_back(source >= 0 ? o.vertex_object[source] : ghost_objects[-1 - source]);
    }
    sub.tets.assign(o.tet_ids.begin(), o.tet_ids.end());
    sub.tet_owned.assign(o.tet_ids.size(), 1);
    sub.tet_object.assign(o.tet_object.begin(), o.tet_object.end());
    sub.local_tets.resize(static_cast<Eigen::Index>(o.tet_ids.size()), 4);
    for (std::size_t t = 0; t < o.tet_ids.size(); ++t)
        for (int k = 0; k < 4; ++k) {
            const int g = o.tet_corners[4 * t + k];
            const auto it = std::lower_bound(sub.vertices.begin(), sub.vertices.end(), g);
            if (it == sub.vertices.end() || *it != g) {
                ++l.missing;
                sub.local_tets(static_cast<Eigen::Index>(t), k) = 0;
            } else {
                sub.local_tets(static_cast<Eigen::Index>(t), k) = static_cast<Index>(it - sub.vertices.begin());
            }
        }
    return l;
}

/// The local positions of a step: owned positions of this step, ghosts from their owners.
void local_positions(const Owned& o, const Local& l, int step, int size, tethash::Positions& local)
{
    const std::size_t owned = o.vertex_ids.size();
    std::vector<double> owned_now(3 * owned);
    for (std::size_t i = 0; i < owned; ++i) {
        const Eigen::RowVector3d p = position_at(o.rest_of(i), o.vertex_object[i], step, o.speed);
        for (int a = 0; a < 3; ++a)
            owned_now[3 * i + a] = p[a];
    }
    std::vector<std::vector<double>> send_pos(static_cast<std::size_t>(size));
    for (int q = 0; q < size; ++q)
        for (int i : l.send_list[q])
            send_pos[q].insert(send_pos[q].end(), owned_now.begin() + 3 * i, owned_now.begin() + 3 * i + 3);
    const std::vector<double> ghost_pos = all_to_all(send_pos, size);
    for (std::size_t k = 0; k < l.order.size(); ++k) {
        const int source = l.order[k].second;
        const double* p = source >= 0 ? &owned_now[3 * static_cast<std::size_t>(source)]
                                      : &ghost_pos[3 * static_cast<std::size_t>(-1 - source)];
        local.row(static_cast<Eigen::Index>(k)) << p[0], p[1], p[2];
    }
}

/// Gathers every rank's contacts of a step on rank 0 and compares them with the serial detection there; returns
/// (on rank 0) whether they differ, and sets `any_contact` when the serial detection found some.
bool gather_and_compare(const std::vector<tethash::Contact>& mine, double ms, std::size_t ghost_count,
                        const Partition& p, tethash::Detector& serial, int step, double speed, int rank, int size,
                        bool& any_contact)
{
    std::vector<int> flat;
    for (const auto& c : mine) {
        flat.push_back(c.vertex);
        flat.push_back(c.tet);
    }
    const int count = static_cast<int>(flat.size());
    std::vector<int> counts(static_cast<std::size_t>(size)), displs(static_cast<std::size_t>(size));
    MPI_Gather(&count, 1, MPI_INT, counts.data(), 1, MPI_INT, 0, MPI_COMM_WORLD);
    int total = 0;
    for (int r = 0; r < size; ++r) {
        displs[r] = total;
        total += counts[r];
    }
    std::vector<int> all(static_cast<std::size_t>(rank == 0 ? total : 0));
    MPI_Gatherv(flat.data(), count, MPI_INT, all.data(), counts.data(), displs.data(), MPI_INT, 0, MPI_COMM_WORLD);
    double ms_max = 0;
    MPI_Reduce(&ms, &ms_max, 1, MPI_DOUBLE, MPI_MAX, 0, MPI_COMM_WORLD);
    int ghosts = static_cast<int>(ghost_count), ghosts_max = 0;
    MPI_Reduce(&ghosts, &ghosts_max, 1, MPI_INT, MPI_MAX, 0, MPI_COMM_WORLD);
    if (rank != 0) return false;
    std::vector<std::pair<Index, Index>> got;
    for (std::size_t i = 0; i + 1 < all.size(); i += 2)
        got.emplace_back(all[i], all[i + 1]);
    std::sort(got.begin(), got.end());
    const auto dup = std::adjacent_find(got.begin(), got.end()) != got.end();
    const tethash::TetMesh& mesh = p.mesh;
    tethash::Positions now = mesh.positions;
    for (Index v = 0; v < mesh.num_vertices(); ++v)
        now.row(v) = position_at(mesh.positions.row(v), mesh.vertex_object[v], step, speed);
    const auto want = pairs_of(serial.detect(now));
    const bool same = got == want;
    std::printf("step %d: %zu contacts from the ranks (per rank:", step, got.size());
    for (int r = 0; r < size; ++r)
        std::printf(" %d", counts[r] / 2);
    std::printf("), serial %zu, %s; most ghosts on a rank %d, slowest rank %.2f ms\n", want.size(),
                same ? "equal" : (dup ? "DIFFERENT (a contact reported twice)" : "DIFFERENT"), ghosts_max, ms_max);
    if (!want.empty()) any_contact = true;
    return !same;
}

int run(int rank, int size, int argc, char** argv)
{
    std::string mesh_path;
    int steps = 3;
    for (int i = 1; i < argc; ++i) {
        const std::string a = argv[i];
        if (a == "--mesh" && i + 1 < argc) {
            mesh_path = argv[++i];
        } else if (a == "--steps" && i + 1 < argc) {
            steps = std::atoi(argv[++i]);
        } else {
            if (rank == 0) std::fprintf(stderr, "mpi_detect: unknown argument '%s'\n%s", argv[i], usage_text);
            return 2;
        }
    }
    if (steps < 1) {
        if (rank == 0) std::fprintf(stderr, "mpi_detect: --steps must be >= 1\n");
        return 2;
    }

    // ---- 1. rank 0: the mesh, the partition, what each rank owns.
    Partition part;
    part.setup.assign(6 * static_cast<std::size_t>(size) + 2, 0.0); // regions, width, speed
    for (auto* lists : {&part.vertex_ids, &part.vertex_object, &part.tet_ids, &part.tet_corners, &part.tet_object})
        lists->assign(static_cast<std::size_t>(size), {});
    part.positions.assign(static_cast<std::size_t>(size), {});
    int ok = 1;
    if (rank == 0) {
        try {
            partition_mesh(mesh_path, size, steps, part);
        } catch (const tethash::Error& e) {
            std::fprintf(stderr, "mpi_detect: %s\n", e.what());
            ok = 0;
        }
    }
    MPI_Bcast(&ok, 1, MPI_INT, 0, MPI_COMM_WORLD);
    if (!ok) return 2;
    MPI_Bcast(part.setup.data(), static_cast<int>(part.setup.size()), MPI_DOUBLE, 0, MPI_COMM_WORLD);
    const Owned owned = scatter_partition(part, rank, size);

    // ---- 2. ghost lists and the local mesh.
    const Local local_mesh = build_local(owned, rank, size);
    int missing_all = 0;
    MPI_Allreduce(&local_mesh.missing, &missing_all, 1, MPI_INT, MPI_SUM, MPI_COMM_WORLD);
    if (missing_all > 0) {
        if (rank == 0) std::fprintf(stderr, "mpi_detect: %d tet corners outside the ghost layers\n", missing_all);
        return 1;
    }
    const tethash::Subdomain& sub = local_mesh.sub;

    // One thread per rank: ranks are the parallelism here (more would oversubscribe the cores the ranks share).
    tethash::DetectParams params;
    params.threads = 1;
    tethash::Detector det(params);
    det.set_topology(sub.local_tets, static_cast<Index>(sub.vertices.size()), sub.vertex_object, sub.tet_object);
    tethash::Positions local(static_cast<Eigen::Index>(sub.vertices.size()), 3);
    std::vector<tethash::Contact> mine;
    tethash::Detector serial;
    if (rank == 0) serial.set_topology(part.mesh);
    int failures = 0;
    bool any_contact = false; // the serial detection found contacts at some step
    for (int step = 0; step < steps; ++step) {
        local_positions(owned, local_mesh, step, size, local);
        // ---- 3. detection on the local mesh, the contacts of owned tets.
        const auto start = std::chrono::steady_clock::now();
        tethash::detect_owned(det, local, sub, tethash::ContactOwner::tet, mine);
        const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
        // ---- 4. gather on rank 0 and compare with the serial detection.
        if (gather_and_compare(mine, ms, local_mesh.ghosts, part, serial, step, owned.speed, rank, size, any_contact))
            ++failures;
    }
    MPI_Bcast(&failures, 1, MPI_INT, 0, MPI_COMM_WORLD);
    if (rank == 0) {
        if (failures)
            std::printf("mpi_detect: FAILED: the ranks' contacts differ from the serial detection at %d of %d steps\n",
                        failures, steps);
        else if (!any_contact)
            std::printf("mpi_detect: no contacts in this mesh at any step (the serial detection finds none either): "
                        "the ranks agree, with nothing to compare; give a mesh whose objects overlap\n");
        else
            std::printf("mpi_detect: the union over ranks equals the serial run\n");
    }
    return failures ? 1 : 0;
}

} // namespace

int main(int argc, char** argv)
{
    // Before MPI_Init: the usage needs no MPI (nor mpirun).
    for (int i = 1; i < argc; ++i)
        if (std::string(argv[i]) == "--help" || std::string(argv[i]) == "-h") {
            std::fputs(usage_text, stdout);
            return 0;
        }
    MPI_Init(&argc, &argv);
    int rank = 0, size = 1;
    MPI_Comm_rank(MPI_COMM_WORLD, &rank);
    MPI_Comm_size(MPI_COMM_WORLD, &size);
    int status = 2;
    try {
        status = run(rank, size, argc, argv);
    } catch (const std::exception& e) {
        std::fprintf(stderr, "mpi_detect (rank %d): %s\n", rank, e.what());
        MPI_Abort(MPI_COMM_WORLD, 2);
    }
    MPI_Finalize();
    return status;
}
