#include "tethash/io/mesh_io.hpp"

#include "tethash/error.hpp"
#include "tethash/io/gmsh.hpp"
#include "tethash/io/surface.hpp"
#include "tethash/io/tetgen.hpp"
#include "tethash/io/vtk.hpp"

#include <algorithm>
#include <atomic>
#include <cctype>
#include <filesystem>
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

TetMesh read_mesh(const std::string& path, ReadNotes* notes)
{
    if (!std::filesystem::exists(path)) throw Error(path + ": no such file");
    if (std::filesystem::is_directory(path)) throw Error(path + ": is a directory, expected a mesh file");
    const std::string e = extension_of(path);
    TetMesh mesh;
    if (e == ".vtk") mesh = read_vtk(path, notes);
    else if (e == ".vtu") mesh = read_vtu(path, notes);
    else if (e == ".msh") mesh = read_msh(path, notes);
    else if (e == ".node" || e == ".ele") mesh = read_tetgen(path, notes);
    else if (e == ".mesh") mesh = read_medit(path, notes);
    else if (e == ".veg") mesh = read_veg(path, notes);
    else if (is_surface_path(path))
        throw Error(path + ": is a surface mesh, not a tet mesh (use 'tethash tetrahedralize' to fill it with tets)");
    else
        throw Error(path + ": unknown mesh format '" + e + "' (expected .vtk .vtu .msh .node .ele .mesh .veg)");
    mesh.check_consistency(path);
    return mesh;
}

void write_mesh(const std::string& path, const TetMesh& mesh, const Fields& fields)
{
    mesh.check_consistency("mesh to write to " + path);
    const std::string e = extension_of(path);
    if (e == ".vtu") write_vtu(path, mesh, fields);
    else if (e == ".vtk") write_vtk(path, mesh, fields);
    else if (e == ".msh") write_msh(path, mesh);
    else if (e == ".mesh") write_medit(path, mesh);
    else if (e == ".node" || e == ".ele") write_tetgen(path, mesh);
    else if (is_surface_path(path)) write_surface(path, boundary_surface(mesh));
    else
        throw Error(path + ": unknown output format '" + e +
                    "' (expected .vtu .vtk .msh .mesh .node, or a surface .obj .ply .stl .gltf .glb)");
}

void write_atomically(const std::string& path, const std::function<void(const std::string&)>& write)
{
    namespace fs = std::filesystem;
    static std::atomic<int> counter{0};
    const fs::path target(path);
    const fs::path dir = target.has_parent_path() ? target.parent_path() : fs::path(".");
    if (!fs::is_directory(dir)) throw Error(path + ": folder '" + dir.string() + "' does not exist");
    std::string name = target.filename().string(); // appended piecewise: g++ 12 warns falsely on "." + string
    name.insert(name.begin(), '.');
    name.append(".tmp").append(std::to_string(::getpid())).append("_").append(std::to_string(counter++));
    const fs::path tmp = dir / name;
    try {
        write(tmp.string());
        std::error_code ec;
        fs::rename(tmp, target, ec);
        if (ec) throw Error(path + ": cannot rename temporary file into place: " + ec.message());
    } catch (...) {
        std::error_code ec;
        fs::remove(tmp, ec);
        throw;
    }
}

} // namespace tethash::io
