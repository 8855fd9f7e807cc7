// Tests of io/surface.hpp: the assimp bridge, tethash's own PLY reader, boundary surfaces.
#include "support.hpp"
#include "surface_support.hpp"

#include "tethash/error.hpp"
#include "tethash/io/mesh_io.hpp"
#include "tethash/io/surface.hpp"
#include "tethash/mesh.hpp"
#include "tethash/meshing/generate.hpp"
#include "tethash/meshing/tetrahedralize.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <numbers>

using namespace tethash;
using tethash::test::enclosed_volume;
using tethash::test::expect_error;
using tethash::test::sphere_surface;
using tethash::test::temp_dir;
using tethash::test::volume;

namespace {

#define SKIP_WITHOUT_ASSIMP()                                                                                          \
    if (!io::have_assimp()) GTEST_SKIP() << "built without assimp"

} // namespace

TEST(Surface, ClassifyPathTellsTetMeshesSurfacesAndOtherFiles)
{
    // Every extension read_mesh reads is a tet mesh, whatever its case and folder; every surface extension a
    // surface; scenes, text and names without an extension neither.
    for (const char* p : {"a.vtk", "dir/b.VTU", "c.msh", "d.node", "e.ele", "f.mesh", "g.veg"}) {
        EXPECT_EQ(io::classify_path(p), io::PathKind::tet_mesh) << p;
        EXPECT_TRUE(io::is_tet_mesh_path(p)) << p;
        EXPECT_FALSE(io::is_surface_path(p)) << p;
    }
    for (const char* p : {"a.obj", "dir/b.STL", "c.ply", "d.off", "e.gltf", "f.glb"}) {
        EXPECT_EQ(io::classify_path(p), io::PathKind::surface) << p;
        EXPECT_FALSE(io::is_tet_mesh_path(p)) << p;
    }
    for (const char* p : {"scene.toml", "notes.txt", "mesh", "", "dir.vtu/file"})
        EXPECT_EQ(io::classify_path(p), io::PathKind::unknown) << p;
}

TEST(Surface, BoundaryOfAGeneratedMeshIsClosedAndOutward)
{
    meshing::GenerateParams p;
    p.shape = "box";
    p.resolution = 5;
    const TetMesh m = meshing::generate(p);
    const io::SurfaceMesh s = meshing::boundary_surface(m);
    EXPECT_EQ(s.triangles.rows(), boundary_faces(m.tets).rows());
    EXPECT_LT(s.vertices.rows(), m.num_vertices()); // interior vertices dropped
    EXPECT_NEAR(enclosed_volume(s), 1.0, 1e-9);     // outward orientation, closed
    // Every surface vertex is used.
    std::vector<int> used(static_cast<std::size_t>(s.vertices.rows()), 0);
    for (Eigen::Index i = 0; i < s.triangles.size(); ++i)
        used[static_cast<std::size_t>(s.triangles.data()[i])] = 1;
    EXPECT_TRUE(std::all_of(used.begin(), used.end(), [](int u) { return u == 1; }));
}

TEST(Surface, RoundTripThroughEveryWrittenFormat)
{
    SKIP_WITHOUT_ASSIMP();
    const io::SurfaceMesh s = sphere_surface(6);
    const auto dir = temp_dir();
    for (const char* ext : {".obj", ".ply", ".stl", ".gltf", ".glb"}) {
        SCOPED_TRACE(ext);
        const std::string path = (dir / (std::string("sphere") + ext)).string();
        io::write_surface(path, s);
        const io::SurfaceMesh r = io::read_surface(path);
        ASSERT_EQ(r.triangles.rows(), s.triangles.rows());
        ASSERT_EQ(r.vertices.rows(), s.vertices.rows()); // shared vertices joined again
        // Every vertex comes back (to float precision; the order may differ).
        for (Eigen::Index i = 0; i < s.vertices.rows(); ++i) {
            double best = 1e300;
            for (Eigen::Index j = 0; j < r.vertices.rows(); ++j)
                best = std::min(best, (s.vertices.row(i) - r.vertices.row(j)).norm());
            ASSERT_LT(best, 1e-6) << "vertex " << i;
        }
        EXPECT_NEAR(enclosed_volume(r), enclosed_volume(s), 1e-5); // same orientation
    }
    // The .gltf refers to its buffer by the final name, and no temporary is left behind.
    EXPECT_TRUE(std::filesystem::exists(dir / "sphere.bin"));
    EXPECT_NE(tethash::test::read_text(dir / "sphere.gltf").find("sphere.bin"), std::string::npos);
    for (const auto& e : std::filesystem::directory_iterator(dir))
        EXPECT_NE(e.path().filename().string()[0], '.') << e.path();
}

TEST(Surface, ReadErrorsNameTheFile)
{
    SKIP_WITHOUT_ASSIMP();
    const auto dir = temp_dir();
    const std::string missing = (dir / "missing.obj").string();
    expect_error([&] { io::read_surface(missing); }, {missing});
    const auto garbage = dir / "garbage.stl";
    tethash::test::write_text(garbage, "solid x\n facet normal 0 0 1\n outer loop\n vertex 0 0\n");
    try {
        io::read_surface(garbage.string());
        FAIL() << "no error";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find(garbage.string()), std::string::npos) << e.what();
    }
    const auto points = dir / "points.obj"; // vertices only: no triangles
    tethash::test::write_text(points, "v 0 0 0\nv 1 0 0\nv 0 1 0\n");
    EXPECT_THROW(io::read_surface(points.string()), Error);
    EXPECT_THROW(io::write_surface((dir / "x.xyz").string(), sphere_surface(4)), Error);
    // An OFF header whose counts the file cannot hold (found by the fuzzer: assimp read "OFF5555555555" as 5.6e9
    // vertices and asked for 15 GB) is refused before the import, naming the file and the count.
    const auto huge = dir / "huge.off";
    tethash::test::write_text(huge, "OFF5555555555\n4 4 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n");
    expect_error([&] { io::read_surface(huge.string()); }, {huge.string(), "5555555555 vertices"});
    const auto faces = dir / "faces.off";
    tethash::test::write_text(faces, "OFF\n# a comment\n4 900000000 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n");
    expect_error([&] { io::read_surface(faces.string()); }, {faces.string(), "900000000 faces"});
}

TEST(Surface, ReadsHandWrittenObjWithQuads)
{
    SKIP_WITHOUT_ASSIMP();
    const auto path = temp_dir() / "cube.obj";
    tethash::test::write_text(path, "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\n"
                                    "f 1 4 3 2\nf 5 6 7 8\nf 1 2 6 5\nf 2 3 7 6\nf 3 4 8 7\nf 4 1 5 8\n");
    const io::SurfaceMesh s = io::read_surface(path.string());
    EXPECT_EQ(s.triangles.rows(), 12);
    EXPECT_EQ(s.vertices.rows(), 8);
    EXPECT_NEAR(enclosed_volume(s), 1.0, 1e-9);
    const TetMesh m = meshing::tetrahedralize(s, {8, true});
    EXPECT_NEAR(volume(m), 1.0, 0.02);
    EXPECT_EQ(validate(m).inverted_tets, 0);
}

TEST(Surface, PlyIsReadByTethashInEveryEncoding)
{
    // .ply does not go through assimp (its 5.2 importer crashes on broken files): ASCII, both binary
    // byte orders, polygons fanned into triangles, extra properties and elements skipped.
    SKIP_WITHOUT_ASSIMP();
    const auto dir = temp_dir();
    const std::string header = "element vertex 4\nproperty float x\nproperty float y\nproperty float z\n"
                               "property uchar red\nelement face 1\nproperty list uchar int vertex_indices\n"
                               "element edge 1\nproperty int a\nproperty int b\nend_header\n";
    const auto expect_square = [](const io::SurfaceMesh& s) {
        ASSERT_EQ(s.vertices.rows(), 4);
        ASSERT_EQ(s.triangles.rows(), 2);
        EXPECT_EQ(s.vertices(2, 0), 1.0);
        EXPECT_EQ(s.vertices(2, 1), 1.0);
        EXPECT_EQ(s.triangles(1, 0), 0);
        EXPECT_EQ(s.triangles(1, 1), 2);
        EXPECT_EQ(s.triangles(1, 2), 3);
    };
    test::write_text(dir / "a.ply", "ply\nformat ascii 1.0\ncomment a square\n" + header +
                                        "0 0 0 9\n1 0 0 9\n1 1 0 9\n0 1 0 9\n4 0 1 2 3\n0 1\n");
    expect_square(io::read_surface((dir / "a.ply").string()));
    for (const bool big : {false, true}) {
        std::string body;
        const auto put = [&](const void* p, std::size_t n) {
            const auto* b = static_cast<const char*>(p);
            for (std::size_t k = 0; k < n; ++k)
                body += b[big ? n - 1 - k : k];
        };
        const float xy[4][2] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
        for (const auto& v : xy) {
            const float z = 0;
            put(&v[0], 4), put(&v[1], 4), put(&z, 4);
            body += '\x09';
        }
        body += '\x04';
        for (std::int32_t i = 0; i < 4; ++i)
            put(&i, 4);
        const std::int32_t edge[2] = {0, 1};
        put(&edge[0], 4), put(&edge[1], 4);
        const auto p = dir / (big ? "be.ply" : "le.ply");
        test::write_text(p, std::string("ply\nformat binary_") + (big ? "big" : "little") + "_endian 1.0\n" + header +
                                body);
        expect_square(io::read_surface(p.string()));
        // Cut inside the faces: an error naming the byte, not a read past the end.
        test::write_text(p, std::string("ply\nformat binary_") + (big ? "big" : "little") + "_endian 1.0\n" + header +
                                body.substr(0, body.size() - 12));
        try {
            io::read_surface(p.string());
            ADD_FAILURE() << "no error for a truncated " << p;
        } catch (const Error& e) {
            EXPECT_NE(std::string(e.what()).find(p.string() + ": byte "), std::string::npos) << e.what();
            EXPECT_NE(std::string(e.what()).find("found the end of the file"), std::string::npos) << e.what();
        }
    }
    const std::vector<std::pair<std::string, std::string>> bad = {
        {"ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nproperty float z\nelement "
         "face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n3 0 0 7\n",
         ":11: face 0: face refers to vertex 7, but there are 1 vertices"},
        {"ply\nformat ascii 1.0\nelement vertex 99999999999\nproperty float x\nend_header\n",
         ":3: element vertex declares 99999999999 items, more than the file"},
        {"ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nend_header\n0 0\n",
         ":3: element vertex has no x, y and z properties"},
        {"ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nproperty float z\n"
         "end_header\n0 nan 0\n",
         ":8: vertex 0: vertex has a non-finite y coordinate"},
        {"ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty float y\nproperty float z\n"
         "end_header\n0 0\n0 0 0\n",
         ":8: vertex 0: expected a number, found the end of the line"},
        {"ply\nformat ascii 1.0\nelement vertex 1\nproperty fl\xff x\nend_header\n",
         ":4: expected 'property TYPE NAME'"},
    };
    for (const auto& [text, fragment] : bad) {
        test::write_text(dir / "bad.ply", text);
        try {
            io::read_surface((dir / "bad.ply").string());
            ADD_FAILURE() << "no error for\n" << text;
        } catch (const Error& e) {
            EXPECT_NE(std::string(e.what()).find((dir / "bad.ply").string() + fragment), std::string::npos) << e.what();
        }
    }
}
