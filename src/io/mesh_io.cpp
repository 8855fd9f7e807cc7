#include "tethash/io/mesh_io.hpp"

#include "tethash/error.hpp"
#include "tethash/io/gmsh.hpp"
#include "tethash/io/surface.hpp"
#include "tethash/io/tetgen.hpp"
#include "tethash/io/vtk.hpp"

#include <algorithm>
#include <atomic>
#include <cctype>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <fcntl.h>
#include <filesystem>
#include <memory>
#include <unistd.h>

namespace tethash::io {

std::string extension_of(const std::string& path)
{
    std::string ext = std::filesystem::path(path).extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
    return ext;
}

bool is_tet_mesh_path(const std::string& path)
{
    const std::string e = extension_of(path);
    return e == ".vtk" || e == ".vtu" || e == ".msh" || e == ".node" || e == ".ele" || e == ".mesh" || e == ".veg";
}

namespace {

/// After --linearize: the mid-edge nodes of quadratic tets are vertices of no tet, and would be found lying on the
/// edges of their tets. Drops every vertex of no tet; the rest keep their order, and notes->vertex_ids their
/// number in the file.
void drop_unused_vertices(TetMesh& mesh, ReadNotes* notes)
{
    const Index n = mesh.num_vertices();
    std::vector<Index> new_index(static_cast<std::size_t>(n), -1);
    for (Index t = 0; t < mesh.num_tets(); ++t)
        for (int k = 0; k < 4; ++k)
            new_index[static_cast<std::size_t>(mesh.tets(t, k))] = 0;
    Index kept = 0;
    for (Index& i : new_index)
        if (i == 0) i = kept++;
    if (kept == n) return;
    const int first = notes ? notes->first_id : 0;
    std::vector<std::int64_t> ids;
    Positions positions(kept, 3), rest(mesh.rest_positions.rows() ? kept : 0, 3);
    std::vector<Index> vertex_object, vertex_label;
    for (Index v = 0; v < n; ++v) {
        const Index i = new_index[static_cast<std::size_t>(v)];
        if (i < 0) continue;
        positions.row(i) = mesh.positions.row(v);
        if (rest.rows()) rest.row(i) = mesh.rest_positions.row(v);
        if (!mesh.vertex_object.empty()) vertex_object.push_back(mesh.vertex_object[static_cast<std::size_t>(v)]);
        if (!mesh.vertex_label.empty()) vertex_label.push_back(mesh.vertex_label[static_cast<std::size_t>(v)]);
        ids.push_back(notes && !notes->vertex_ids.empty() ? notes->vertex_ids[static_cast<std::size_t>(v)]
                                                          : std::int64_t{first} + v);
    }
    for (Index t = 0; t < mesh.num_tets(); ++t)
        for (int k = 0; k < 4; ++k)
            mesh.tets(t, k) = new_index[static_cast<std::size_t>(mesh.tets(t, k))];
    mesh.positions = std::move(positions);
    mesh.rest_positions = std::move(rest);
    mesh.vertex_object = std::move(vertex_object);
    mesh.vertex_label = std::move(vertex_label);
    if (notes) {
        notes->vertex_ids = std::move(ids);
        notes->messages.push_back("--linearize: " + std::to_string(n - kept) +
                                  " nodes of no tet (mid-edge nodes) dropped; vertex ids in output count the " +
                                  std::to_string(kept) + " kept nodes");
    }
}

} // namespace

TetMesh read_mesh(const std::string& path, ReadNotes* notes, const ReadOptions& options)
{
    if (!std::filesystem::exists(path)) throw Error(path + ": no such file");
    if (std::filesystem::is_directory(path)) throw Error(path + ": is a directory, expected a mesh file");
    const std::string e = extension_of(path);
    TetMesh mesh;
    if (e == ".vtk")
        mesh = read_vtk(path, notes, options);
    else if (e == ".vtu")
        mesh = read_vtu(path, notes, options);
    else if (e == ".msh")
        mesh = read_msh(path, notes, options);
    else if (e == ".node" || e == ".ele")
        mesh = read_tetgen(path, notes);
    else if (e == ".mesh")
        mesh = read_medit(path, notes);
    else if (e == ".veg")
        mesh = read_veg(path, notes);
    else if (is_surface_path(path))
        throw Error(path + ": is a surface mesh, not a tet mesh (use 'tethash tetrahedralize' to fill it with tets)");
    else
        throw Error(path + ": unknown mesh format '" + e + "' (expected .vtk .vtu .msh .node .ele .mesh .veg)");
    mesh.check_consistency(path);
    if (notes && (e == ".msh" || e == ".mesh" || e == ".veg")) notes->first_id = 1;
    if (options.linearize) drop_unused_vertices(mesh, notes);
    return mesh;
}

TetMesh read_tet_mesh(const std::string& path, ReadNotes* notes, const ReadOptions& options)
{
    ReadNotes local;
    ReadNotes& n = notes ? *notes : local;
    const std::size_t first_skipped = n.skipped.size();
    TetMesh mesh = read_mesh(path, &n, options);
    if (mesh.num_tets() > 0) return mesh;
    std::string held;
    bool quadratic = false;
    for (std::size_t k = first_skipped; k < n.skipped.size(); ++k) {
        const SkippedCells& s = n.skipped[k];
        held += (held.empty() ? "" : ", ") + std::to_string(s.count) + " cells of " + s.kind;
        quadratic = quadratic || s.quadratic_tets;
    }
    if (held.empty()) held = "no cells";
    std::string message = path + ": no tets to work on: the file holds " + std::to_string(mesh.num_vertices()) +
                          " points and " + held + "; tethash needs 4-node tets";
    if (quadratic) message += "; use the corner nodes of the quadratic tets with --linearize";
    throw Error(message);
}

void write_mesh(const std::string& path, const TetMesh& mesh, const Fields& fields)
{
    mesh.check_consistency("mesh to write to " + path);
    const std::string e = extension_of(path);
    if (e == ".vtu")
        write_vtu(path, mesh, fields);
    else if (e == ".vtk")
        write_vtk(path, mesh, fields);
    else if (e == ".msh")
        write_msh(path, mesh);
    else if (e == ".mesh")
        write_medit(path, mesh);
    else if (e == ".node" || e == ".ele")
        write_tetgen(path, mesh);
    else if (is_surface_path(path))
        write_surface(path, boundary_surface(mesh));
    else
        throw Error(path + ": unknown output format '" + e +
                    "' (expected .vtu .vtk .msh .mesh .node, or a surface .obj .ply .stl .gltf .glb)");
}

namespace {

namespace fs = std::filesystem;

/// Folder that will hold `target` ("." for a bare file name).
fs::path folder_of(const fs::path& target)
{
    return target.has_parent_path() ? target.parent_path() : fs::path(".");
}

/// A unique hidden temporary name next to `target`.
fs::path temporary_for(const fs::path& target)
{
    static std::atomic<int> counter{0};
    std::string name = target.filename().string(); // appended piecewise: g++ 12 warns falsely on "." + string
    name.insert(name.begin(), '.');
    name.append(".tmp").append(std::to_string(::getpid())).append("_").append(std::to_string(counter++));
    return folder_of(target) / name;
}

/// `text` with every occurrence of `from` replaced by `to`.
std::string replace_all(std::string text, const std::string& from, const std::string& to)
{
    if (from.empty()) return text;
    for (std::size_t at = text.find(from); at != std::string::npos; at = text.find(from, at + to.size()))
        text.replace(at, from.size(), to);
    return text;
}

/// Temporary files being written, for remove_temporaries_now(): fixed slots so that a signal handler
/// can walk them without locks or allocation. A path that does not fit or finds no slot is not tracked.
struct TemporarySlot {
    std::atomic<bool> used{false};
    char path[4096] = {};
};
TemporarySlot g_temporaries[16];
std::atomic<bool> g_claimed[16];

/// Tracks `path` while alive.
class TrackedTemporary {
  public:
    explicit TrackedTemporary(const std::string& path)
    {
        if (path.size() >= sizeof(TemporarySlot::path)) return;
        for (int i = 0; i < 16; ++i) {
            bool expected = false;
            if (g_claimed[i].compare_exchange_strong(expected, true)) {
                std::memcpy(g_temporaries[i].path, path.c_str(), path.size() + 1);
                g_temporaries[i].used.store(true, std::memory_order_release);
                m_slot = i;
                return;
            }
        }
    }
    ~TrackedTemporary()
    {
        if (m_slot < 0) return;
        g_temporaries[m_slot].used.store(false, std::memory_order_release);
        g_claimed[m_slot].store(false);
    }
    TrackedTemporary(const TrackedTemporary&) = delete;
    TrackedTemporary& operator=(const TrackedTemporary&) = delete;

  private:
    int m_slot = -1;
};

void check_target(const std::string& path)
{
    const fs::path target(path);
    if (path.empty()) throw Error("empty output file name");
    if (fs::is_directory(target)) throw Error(path + ": is a directory, expected a file name");
    const fs::path dir = folder_of(target);
    if (!fs::exists(dir)) throw Error(path + ": folder '" + dir.string() + "' does not exist");
    if (!fs::is_directory(dir)) throw Error(path + ": '" + dir.string() + "' is not a folder");
}

} // namespace

void write_atomically(const std::vector<std::string>& paths,
                      const std::function<void(const std::vector<std::string>&)>& write)
{
    for (const std::string& p : paths)
        check_target(p);
    std::vector<std::string> tmps;
    for (const std::string& p : paths)
        tmps.push_back(temporary_for(p).string());
    std::vector<std::unique_ptr<TrackedTemporary>> tracked;
    for (const std::string& t : tmps)
        tracked.push_back(std::make_unique<TrackedTemporary>(t));
    auto remove_temporaries = [&] {
        for (const std::string& t : tmps) {
            std::error_code ec;
            fs::remove(t, ec);
        }
    };
    try {
        write(tmps);
        for (std::size_t i = 0; i < paths.size(); ++i) {
            std::error_code ec;
            fs::rename(tmps[i], paths[i], ec);
            if (ec) throw Error(paths[i] + ": cannot move the temporary file into place: " + ec.message());
        }
    } catch (const Error& e) {
        remove_temporaries();
        std::string msg = e.what();
        for (std::size_t i = 0; i < paths.size(); ++i)
            msg = replace_all(msg, tmps[i], paths[i]);
        throw Error(msg);
    } catch (...) {
        remove_temporaries();
        throw;
    }
}

void remove_temporaries_now() noexcept
{
    for (auto& slot : g_temporaries)
        if (slot.used.load(std::memory_order_acquire)) ::unlink(slot.path);
}

void write_atomically(const std::string& path, const std::function<void(const std::string&)>& write)
{
    write_atomically(std::vector<std::string>{path}, [&](const std::vector<std::string>& tmps) { write(tmps[0]); });
}

void write_text_file(const std::string& path, const std::string& text)
{
    write_atomically(path, [&](const std::string& tmp) {
        std::FILE* f = std::fopen(tmp.c_str(), "wb");
        if (!f) throw Error(path + ": cannot create file: " + std::strerror(errno));
        errno = 0;
        const bool wrote = std::fwrite(text.data(), 1, text.size(), f) == text.size();
        const bool flushed = std::fflush(f) == 0;
        const int err = errno;
        const bool closed = std::fclose(f) == 0;
        if (!wrote || !flushed || !closed) throw Error(path + ": write failed: " + std::strerror(err ? err : EIO));
    });
}

void check_output_file(const std::string& path, const std::string& what)
{
    try {
        check_target(path);
    } catch (const Error& e) {
        throw Error(what + ": " + e.what());
    }
    // Probe the folder: permissions, read-only file systems and special folders all show up here.
    const fs::path probe = temporary_for(fs::path(path));
    const int fd = ::open(probe.c_str(), O_WRONLY | O_CREAT | O_EXCL, 0600);
    if (fd < 0)
        throw Error(what + ": " + path + ": cannot create files in folder '" + folder_of(fs::path(path)).string() +
                    "': " + std::strerror(errno));
    ::close(fd);
    ::unlink(probe.c_str());
}

void check_mesh_output_file(const std::string& path, const std::string& what)
{
    const std::string e = extension_of(path);
    const bool tet = e == ".vtu" || e == ".vtk" || e == ".msh" || e == ".mesh" || e == ".node" || e == ".ele";
    const bool surface = e == ".obj" || e == ".ply" || e == ".stl" || e == ".gltf" || e == ".glb";
    if (!fs::is_directory(path) && !tet && !surface)
        throw Error(what + ": " + path + ": unknown output format '" + e +
                    "' (expected .vtu .vtk .msh .mesh .node, or a surface .obj .ply .stl .gltf .glb)");
    if (surface && !have_assimp())
        throw Error(what + ": " + path + ": cannot write surfaces: tethash was built without assimp");
    check_output_file(path, what);
}

} // namespace tethash::io
