// Triangle surfaces through assimp (import: every mesh of the scene with its node transform;
// export: one mesh, written through a private folder so side files get their final names).
#include "tethash/io/surface.hpp"

#include "ply.hpp"
#include "tethash/error.hpp"

#include <algorithm>
#include <array>
#include <atomic>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <unistd.h>

#ifdef TETHASH_HAVE_ASSIMP
#include <assimp/DefaultIOSystem.h>
#include <assimp/Exporter.hpp>
#include <assimp/IOStream.hpp>
#include <assimp/Importer.hpp>
#include <assimp/postprocess.h>
#include <assimp/scene.h>
#endif

namespace tethash::io {

bool is_surface_path(const std::string& path)
{
    const std::string e = extension_of(path);
    return e == ".obj" || e == ".stl" || e == ".ply" || e == ".off" || e == ".gltf" || e == ".glb" || e == ".fbx" ||
           e == ".dae" || e == ".3ds";
}

namespace {

/// Wavefront OBJ written here rather than by assimp, whose exporter adds per-corner normal indices that
/// meshio cannot read: only "v x y z" and "f a b c" (1-based, shared vertices), one surface for every reader.
void write_obj(const std::string& path, const SurfaceMesh& surface)
{
    std::string text = "# boundary surface written by tethash: " + std::to_string(surface.vertices.rows()) +
                       " vertices, " + std::to_string(surface.triangles.rows()) + " triangles\n";
    char buf[96];
    for (Eigen::Index v = 0; v < surface.vertices.rows(); ++v) {
        std::snprintf(buf, sizeof buf, "v %.17g %.17g %.17g\n", surface.vertices(v, 0), surface.vertices(v, 1),
                      surface.vertices(v, 2));
        text += buf;
    }
    for (Eigen::Index t = 0; t < surface.triangles.rows(); ++t) {
        std::snprintf(buf, sizeof buf, "f %d %d %d\n", surface.triangles(t, 0) + 1, surface.triangles(t, 1) + 1,
                      surface.triangles(t, 2) + 1);
        text += buf;
    }
    write_text_file(path, text);
}

} // namespace

#ifdef TETHASH_HAVE_ASSIMP

bool have_assimp()
{
    return true;
}

namespace {

/// Deepest node nesting followed (surface formats use a few levels; the walk is recursive).
constexpr int k_max_node_depth = 256;

void collect(const std::string& path, const aiScene* scene, const aiNode* node, const aiMatrix4x4& parent, int depth,
             std::vector<double>& xyz, std::vector<Index>& tri)
{
    if (depth > k_max_node_depth)
        throw Error(path + ": the scene nests nodes more than " + std::to_string(k_max_node_depth) + " deep");
    const aiMatrix4x4 m = parent * node->mTransformation;
    for (unsigned i = 0; i < node->mNumMeshes; ++i) {
        if (node->mMeshes[i] >= scene->mNumMeshes)
            throw Error(path + ": a node refers to mesh " + std::to_string(node->mMeshes[i]) + ", but the file has " +
                        std::to_string(scene->mNumMeshes));
        const aiMesh* mesh = scene->mMeshes[node->mMeshes[i]];
        const auto base = static_cast<Index>(xyz.size() / 3);
        for (unsigned v = 0; v < mesh->mNumVertices; ++v) {
            const aiVector3D p = m * mesh->mVertices[v];
            xyz.insert(xyz.end(), {double(p.x), double(p.y), double(p.z)});
        }
        for (unsigned f = 0; f < mesh->mNumFaces; ++f) {
            const aiFace& face = mesh->mFaces[f];
            if (face.mNumIndices != 3) continue; // points and lines
            for (int k = 0; k < 3; ++k) {
                if (face.mIndices[k] >= mesh->mNumVertices)
                    throw Error(path + ": face " + std::to_string(f) + " refers to vertex " +
                                std::to_string(face.mIndices[k]) + ", but its mesh has " +
                                std::to_string(mesh->mNumVertices) + " vertices");
                tri.push_back(base + static_cast<Index>(face.mIndices[k]));
            }
        }
    }
    for (unsigned c = 0; c < node->mNumChildren; ++c)
        collect(path, scene, node->mChildren[c], m, depth + 1, xyz, tri);
}

/// An OFF file's declared vertex and face counts against its size, before assimp sizes its arrays by them (its
/// importer reads "OFF5555555555" as 5.6e9 vertices and asks for 15 GB): each vertex takes at least 5 bytes
/// ("0 0 0"), each face 7 ("3 0 1 2").
void check_off_counts(const std::string& path)
{
    std::FILE* f = std::fopen(path.c_str(), "rb");
    if (!f) return; // assimp says why
    char head[512] = {};
    const std::size_t got = std::fread(head, 1, sizeof head - 1, f);
    std::fclose(f);
    const std::string text(head, got);
    const std::size_t off = text.find("OFF");
    if (off == std::string::npos) return;
    const double size = static_cast<double>(std::filesystem::file_size(path));
    const char* p = text.c_str() + off + 3;
    const char* names[2] = {"vertices", "faces"};
    const double least[2] = {5, 7};
    for (int k = 0; k < 2; ++k) {
        while (*p != 0 && (std::isspace(static_cast<unsigned char>(*p)) != 0 || *p == '#')) {
            if (*p == '#') // a comment line
                while (*p != 0 && *p != '\n')
                    ++p;
            else
                ++p;
        }
        char* end = nullptr;
        const double n = std::strtod(p, &end);
        if (end == p) return; // not a count: assimp says why
        if (n * least[k] > size)
            throw Error(path + ": the OFF header declares " + std::to_string(static_cast<long long>(n)) + " " +
                        names[k] + ", more than the file's " + std::to_string(static_cast<long long>(size)) +
                        " bytes can hold");
        p = end;
    }
}

/// Every triangle of the scene with its node transform applied, as a soup (vertices per mesh).
void import_with_assimp(const std::string& path, std::vector<double>& xyz, std::vector<Index>& tri)
{
    Assimp::Importer importer;
    // Validation runs before the other steps: without it a face index past the vertices crashes inside
    // assimp's post-processing.
    const aiScene* scene = importer.ReadFile(path, aiProcess_ValidateDataStructure | aiProcess_Triangulate |
                                                       aiProcess_JoinIdenticalVertices);
    if (!scene || !scene->mRootNode) throw Error(path + ": cannot read surface: " + importer.GetErrorString());
    collect(path, scene, scene->mRootNode, aiMatrix4x4(), 0, xyz, tri);
}

} // namespace

SurfaceMesh read_surface(const std::string& path)
{
    if (!std::filesystem::exists(path)) throw Error(path + ": no such file");
    if (std::filesystem::is_directory(path)) throw Error(path + ": is a directory, expected a surface file");
    std::vector<double> xyz;
    std::vector<Index> tri;
    if (extension_of(path) == ".ply")
        detail::read_ply(path, xyz, tri); // assimp 5.2's PLY importer crashes on broken files
    else {
        if (extension_of(path) == ".off") check_off_counts(path);
        import_with_assimp(path, xyz, tri);
    }
    if (tri.empty()) throw Error(path + ": no triangles in the file");
    // Before the join: NaN compares unequal to itself, which stalled the loop below (and breaks the sort).
    for (std::size_t i = 0; i < xyz.size(); ++i)
        if (!std::isfinite(xyz[i]))
            throw Error(path + ": vertex " + std::to_string(i / 3) + " has a non-finite coordinate");
    // Join vertices at identical positions (assimp keeps STL corners apart: they differ in their normals),
    // keeping the first occurrence's order.
    const std::size_t nv = xyz.size() / 3;
    std::vector<std::size_t> order(nv);
    for (std::size_t i = 0; i < nv; ++i)
        order[i] = i;
    auto key = [&](std::size_t i) { return std::array<double, 3>{xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2]}; };
    std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return key(a) < key(b); });
    std::vector<std::size_t> rep(nv);
    for (std::size_t i = 0; i < nv;) {
        std::size_t j = i;
        while (j < nv && key(order[j]) == key(order[i]))
            rep[order[j++]] = order[i];
        i = j;
    }
    std::vector<Index> new_id(nv, -1);
    Index n = 0;
    for (std::size_t i = 0; i < nv; ++i)
        if (rep[i] == i) new_id[i] = n++;
    SurfaceMesh s;
    s.vertices.resize(n, 3);
    for (std::size_t i = 0; i < nv; ++i)
        if (rep[i] == i) s.vertices.row(new_id[i]) << xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2];
    s.triangles.resize(static_cast<Eigen::Index>(tri.size() / 3), 3);
    for (std::size_t t = 0; t < tri.size(); ++t)
        s.triangles(static_cast<Eigen::Index>(t / 3), static_cast<Eigen::Index>(t % 3)) =
            new_id[rep[static_cast<std::size_t>(tri[t])]];
    return s;
}

namespace {

/// assimp's own file streams ignore write errors (a full disk gives a truncated file and success);
/// these streams record the first error so that the export can be refused.
class CheckedWriteStream : public Assimp::IOStream {
  public:
    CheckedWriteStream(std::FILE* f, std::string* error) : m_file(f), m_error(error) {}
    ~CheckedWriteStream() override
    {
        if (std::fflush(m_file) != 0) fail();
        if (std::fclose(m_file) != 0) fail();
    }
    size_t Read(void* buffer, size_t size, size_t count) override { return std::fread(buffer, size, count, m_file); }
    size_t Write(const void* buffer, size_t size, size_t count) override
    {
        const size_t n = std::fwrite(buffer, size, count, m_file);
        if (n != count) fail();
        return n;
    }
    aiReturn Seek(size_t offset, aiOrigin origin) override
    {
        const int whence = origin == aiOrigin_SET ? SEEK_SET : origin == aiOrigin_CUR ? SEEK_CUR : SEEK_END;
        return std::fseek(m_file, static_cast<long>(offset), whence) == 0 ? aiReturn_SUCCESS : aiReturn_FAILURE;
    }
    size_t Tell() const override { return static_cast<size_t>(std::ftell(m_file)); }
    size_t FileSize() const override
    {
        const long here = std::ftell(m_file);
        std::fseek(m_file, 0, SEEK_END);
        const long size = std::ftell(m_file);
        std::fseek(m_file, here, SEEK_SET);
        return static_cast<size_t>(size);
    }
    void Flush() override
    {
        if (std::fflush(m_file) != 0) fail();
    }

  private:
    void fail()
    {
        if (m_error->empty()) m_error->assign(std::strerror(errno ? errno : EIO));
    }
    std::FILE* m_file;
    std::string* m_error;
};

class CheckedIOSystem : public Assimp::DefaultIOSystem {
  public:
    explicit CheckedIOSystem(std::string* error) : m_error(error) {}
    Assimp::IOStream* Open(const char* file, const char* mode) override
    {
        if (std::strchr(mode, 'w') == nullptr && std::strchr(mode, 'a') == nullptr)
            return Assimp::DefaultIOSystem::Open(file, mode);
        std::FILE* f = std::fopen(file, mode);
        if (!f) {
            if (m_error->empty()) m_error->assign(std::string("cannot create ") + file + ": " + std::strerror(errno));
            return nullptr;
        }
        return new CheckedWriteStream(f, m_error);
    }

  private:
    std::string* m_error;
};

} // namespace

void write_surface(const std::string& path, const SurfaceMesh& surface)
{
    namespace fs = std::filesystem;
    const std::string e = extension_of(path);
    std::string format;
    if (e == ".obj")
        format = "objnomtl";
    else if (e == ".ply")
        format = "plyb";
    else if (e == ".stl")
        format = "stlb";
    else if (e == ".gltf")
        format = "gltf2";
    else if (e == ".glb")
        format = "glb2";
    else
        throw Error(path + ": unknown surface format '" + e + "' (expected .obj .ply .stl .gltf .glb)");
    if (surface.triangles.rows() == 0) throw Error(path + ": surface to write has no triangles");
    const auto nv = static_cast<unsigned>(surface.vertices.rows());
    for (Eigen::Index t = 0; t < surface.triangles.rows(); ++t)
        for (int k = 0; k < 3; ++k)
            if (surface.triangles(t, k) < 0 || static_cast<unsigned>(surface.triangles(t, k)) >= nv)
                throw Error(path + ": surface triangle " + std::to_string(t) + " has vertex index " +
                            std::to_string(surface.triangles(t, k)) + " out of range");
    if (e == ".obj") return write_obj(path, surface);

    // The scene owns (and its destructor frees) everything allocated below.
    aiScene scene;
    scene.mRootNode = new aiNode();
    scene.mRootNode->mName = "tethash";
    scene.mMaterials = new aiMaterial* [1] { new aiMaterial() };
    scene.mNumMaterials = 1;
    auto* mesh = new aiMesh();
    scene.mMeshes = new aiMesh* [1] { mesh };
    scene.mNumMeshes = 1;
    scene.mRootNode->mMeshes = new unsigned[1]{0};
    scene.mRootNode->mNumMeshes = 1;
    mesh->mMaterialIndex = 0;
    mesh->mPrimitiveTypes = aiPrimitiveType_TRIANGLE;
    mesh->mNumVertices = nv;
    mesh->mVertices = new aiVector3D[nv];
    for (unsigned v = 0; v < nv; ++v)
        mesh->mVertices[v] =
            aiVector3D(static_cast<ai_real>(surface.vertices(v, 0)), static_cast<ai_real>(surface.vertices(v, 1)),
                       static_cast<ai_real>(surface.vertices(v, 2)));
    const auto nf = static_cast<unsigned>(surface.triangles.rows());
    mesh->mNumFaces = nf;
    mesh->mFaces = new aiFace[nf];
    for (unsigned f = 0; f < nf; ++f) {
        mesh->mFaces[f].mNumIndices = 3;
        mesh->mFaces[f].mIndices = new unsigned[3];
        for (int k = 0; k < 3; ++k)
            mesh->mFaces[f].mIndices[k] = static_cast<unsigned>(surface.triangles(f, k));
    }

    write_atomically(path, [&](const std::string& tmp) {
        // Export under the final file name inside a private folder next to the target: formats with
        // side files (.gltf + .bin) then refer to them by their final names.
        static std::atomic<int> counter{0};
        const fs::path target(path);
        const fs::path dir = fs::path(tmp).parent_path();
        const fs::path work = dir / (".tethash_export" + std::to_string(::getpid()) + "_" + std::to_string(counter++));
        fs::create_directories(work);
        struct Cleanup {
            fs::path p;
            ~Cleanup()
            {
                std::error_code ec;
                fs::remove_all(p, ec);
            }
        } cleanup{work};
        const fs::path main_file = work / target.filename();
        std::string io_error;
        {
            Assimp::Exporter exporter;
            exporter.SetIOHandler(new CheckedIOSystem(&io_error)); // the exporter owns it
            if (exporter.Export(&scene, format, main_file.string()) != aiReturn_SUCCESS) {
                if (!io_error.empty()) throw WriteError(path + ": write failed: " + io_error);
                throw Error(path + ": cannot write surface: " + exporter.GetErrorString());
            }
        }
        if (!io_error.empty()) throw WriteError(path + ": write failed: " + io_error);
        if (!fs::exists(main_file)) throw Error(path + ": assimp wrote no file");
        for (const auto& entry : fs::directory_iterator(work)) {
            if (entry.path() == main_file) continue;
            fs::rename(entry.path(), dir / entry.path().filename()); // side file (e.g. the .bin of a .gltf)
        }
        fs::rename(main_file, tmp);
    });
}

#else

bool have_assimp()
{
    return false;
}
SurfaceMesh read_surface(const std::string& path)
{
    throw Error(path + ": cannot read surfaces: tethash was built without assimp");
}
void write_surface(const std::string& path, const SurfaceMesh& surface)
{
    if (extension_of(path) == ".obj") return write_obj(path, surface);
    throw Error(path + ": cannot write surfaces other than .obj: tethash was built without assimp");
}

#endif

} // namespace tethash::io
