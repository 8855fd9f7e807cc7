// Scene files: every key read, defaults, the shipped scenes parse, bad keys and types name key and line.
#include "support.hpp"

#include "tethash/error.hpp"
#include "tethash/sim/scene.hpp"
#include "tethash/sim/simulation.hpp"

#include <filesystem>

using namespace tethash;
using tethash::test::expect_error;
using namespace tethash::sim;

namespace {
std::string error_of(const std::string& text)
{
    try {
        parse_scene(text, "s.toml", ".");
    } catch (const Error& e) {
        return e.what();
    }
    return "";
}
const std::string kObject = "\n[[object]]\ngenerate = { shape = \"box\", resolution = 2 }\n";
} // namespace

TEST(SimScene, ReadsEveryKey)
{
    const Scene s = parse_scene(R"(
dt = 0.005
steps = 12
substeps = 3
max_substeps = 12
integrator = "vbd"
solver = "ldlt"
iterations = 7
acceleration = 0.75
inversion_guard = true
tolerance = 1e-8
gravity = [0, -9.8, 0]
[ground]
height = 0.5
normal = [0, 2, 0]
friction = 0.25
[contact]
stiffness = 1e5
damping = 3
friction = 0.1
in_matrix = false
[detector]
cell_size = "x1.5"
table_size = 1009
hash = "teschner"
threads = 1
[output]
every = 4
fields = ["velocity", "depth"]
[[object]]
name = "a"
generate = { shape = "bar", resolution = 5, size = [2, 0.5, 0.5] }
scale = 2
rotate = [0, 90, 0]
translate = [1, 2, 3]
velocity = [0, 0, -1]
self_collision = false
material = { density = 7, young = 8, damping = 0.5, volume_stiffness = 0.25 }
[[object]]
mesh = "sub/thing.vtu"
static = true
[[pin]]
object = 0
vertices = [0, 3]
box_min = [0, 0, 0]
box_max = [1, 1, 1]
)",
                                "s.toml", "/base");
    EXPECT_EQ(s.dt, 0.005);
    EXPECT_EQ(s.steps, 12);
    EXPECT_EQ(s.substeps, 3);
    EXPECT_EQ(s.max_substeps, 12);
    EXPECT_EQ(s.integrator, Integrator::vbd);
    EXPECT_EQ(s.solver, LinearSolver::ldlt);
    EXPECT_EQ(s.iterations, 7);
    EXPECT_EQ(s.acceleration, 0.75);
    EXPECT_TRUE(s.inversion_guard);
    EXPECT_EQ(s.gravity.y(), -9.8);
    EXPECT_TRUE(s.ground.enabled);
    EXPECT_NEAR(s.ground.normal.y(), 1.0, 1e-15);
    EXPECT_EQ(s.contact.stiffness, 1e5);
    EXPECT_FALSE(s.contact.in_matrix);
    EXPECT_EQ(s.detect.cell_size_mode, DetectParams::CellSizeMode::factor_of_mean_edge);
    EXPECT_EQ(s.detect.cell_size, 1.5);
    EXPECT_EQ(s.detect.table_size, 1009);
    EXPECT_EQ(s.detect.hash, HashFunction::teschner);
    EXPECT_EQ(s.output.every, 4);
    EXPECT_EQ(s.output.fields.size(), 2u);
    ASSERT_EQ(s.objects.size(), 2u);
    EXPECT_EQ(s.objects[0].name, "a");
    ASSERT_TRUE(s.objects[0].generate.has_value());
    EXPECT_EQ(s.objects[0].generate->shape, "bar");
    EXPECT_EQ(s.objects[0].generate->size.x(), 2);
    EXPECT_EQ(s.objects[0].scale.z(), 2);
    EXPECT_EQ(s.objects[0].translate.z(), 3);
    EXPECT_FALSE(s.objects[0].self_collision);
    EXPECT_EQ(s.objects[0].material.volume_stiffness, 0.25);
    EXPECT_EQ(s.objects[1].mesh, "/base/sub/thing.vtu");
    EXPECT_TRUE(s.objects[1].is_static);
    ASSERT_EQ(s.pins.size(), 1u);
    EXPECT_EQ(s.pins[0].vertices.size(), 2u);
    EXPECT_TRUE(s.pins[0].has_box);
}

TEST(SimScene, UnknownKeysNameKeyAndLine)
{
    std::string e = error_of("dt = 0.01\nstepz = 4\n" + kObject);
    EXPECT_NE(e.find("s.toml:2"), std::string::npos) << e;
    EXPECT_NE(e.find("stepz"), std::string::npos) << e;
    e = error_of(kObject + "material = { densty = 3 }\n");
    EXPECT_NE(e.find("s.toml:4"), std::string::npos) << e;
    EXPECT_NE(e.find("object[0].material.densty"), std::string::npos) << e;
    e = error_of("[ground]\nhieght = 1\n" + kObject);
    EXPECT_NE(e.find("s.toml:2"), std::string::npos) << e;
    EXPECT_NE(e.find("ground.hieght"), std::string::npos) << e;
}

TEST(SimScene, WrongTypesAndValuesNameKeyAndLine)
{
    struct Case {
        std::string text, key, line;
    } cases[] = {
        {"dt = \"fast\"\n" + kObject, "'dt'", "s.toml:1"},
        {"\n\nsteps = 2.5\n" + kObject, "'steps'", "s.toml:3"},
        {"dt = -1\n" + kObject, "'dt'", "s.toml:1"},
        {"gravity = [0, 1]\n" + kObject, "'gravity'", "s.toml:1"},
        {"integrator = \"rk4\"\n" + kObject, "'integrator'", "s.toml:1"},
        {kObject + "self_collision = 1\n", "object[0].self_collision", "s.toml:4"},
        {"[[object]]\ngenerate = { shape = \"cube\" }\n", "object[0].generate.shape", "s.toml:2"},
        {"[detector]\ncell_size = \"big\"\n" + kObject, "detector.cell_size", "s.toml:2"},
        {"[[object]]\nname = \"x\"\n", "object[0]", "s.toml:"},
        {"dt = = 1\n", "TOML", "s.toml:1"},
        {"\nacceleration = 1\n" + kObject, "'acceleration'", "s.toml:2"},
        {"inversion_guard = 1\n" + kObject, "'inversion_guard'", "s.toml:1"},
        {"[detector]\nthreads = 100000\n" + kObject, "detector.threads", "s.toml:2"},
        {"[detector]\ntable_size = \"x0\"\n" + kObject, "detector.table_size", "s.toml:2"},
        {"[detector]\nskin = \"x-1\"\n" + kObject, "detector.skin", "s.toml:2"},
        {"[detector]\nmethod = \"octtree\"\n" + kObject, "detector.method", "s.toml:2"},
        {"[detector]\nmethod = 3\n" + kObject, "detector.method", "s.toml:2"},
        {"[detector]\nmax_depth = 99\n" + kObject, "detector.max_depth", "s.toml:2"},
        {"[detector]\nmax_depth = 0\n" + kObject, "detector.max_depth", "s.toml:2"},
        {"[detector]\nlooseness = 0.5\n" + kObject, "detector.looseness", "s.toml:2"},
        {"[detector]\nlevels = 33\n" + kObject, "detector.levels", "s.toml:2"},
    };
    for (const Case& c : cases) {
        const std::string e = error_of(c.text);
        EXPECT_NE(e.find(c.key), std::string::npos) << c.text << " -> " << e;
        EXPECT_NE(e.find(c.line), std::string::npos) << c.text << " -> " << e;
    }
}

TEST(SimScene, DetectorKeysUseTheCommandLineGrammar)
{
    // Strings mean what they mean on the command line (detect.hpp): "xF" factors, "auto", plain lengths.
    Scene s = parse_scene("[detector]\ncell_size = \"0.25\"\nskin = \"x0.5\"\ntable_size = \"x2\"\n" + kObject,
                          "s.toml", ".");
    EXPECT_EQ(s.detect.cell_size_mode, DetectParams::CellSizeMode::absolute);
    EXPECT_DOUBLE_EQ(s.detect.cell_size, 0.25);
    EXPECT_EQ(s.detect.skin_mode, DetectParams::SkinMode::factor_of_cell_size);
    EXPECT_DOUBLE_EQ(s.detect.skin, 0.5);
    EXPECT_EQ(s.table_size_of_vertices, "x2");
    // "xF" is resolved against the scene's vertex count when the simulation is built, as `detect --table-size xF`
    // does: a factor too large for this scene is refused there, naming the key.
    s.output.every = 0;
    EXPECT_NO_THROW(Simulation{s});
    s = parse_scene("[detector]\ntable_size = \"x1e17\"\n" + kObject, "s.toml", ".");
    try {
        Simulation sim(s);
        ADD_FAILURE() << "a table of 1e17 × the vertices was accepted";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("detector.table_size"), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find("largest table"), std::string::npos) << e.what();
    }
    s = parse_scene("[detector]\ntable_size = \"auto\"\nthreads = 0\n" + kObject, "s.toml", ".");
    EXPECT_EQ(s.detect.table_size, 0);
    EXPECT_TRUE(s.table_size_of_vertices.empty());
    EXPECT_EQ(s.detect.threads, 0);
}

TEST(SimScene, DetectorMethodKeys)
{
    // The broad phase and its parameters, in the grammar of `detect --method` (detect.hpp: parse_method).
    Scene s = parse_scene(
        "[detector]\nmethod = \"brute\"\nmax_depth = 7\nleaf_size = 3\nlooseness = 1.5\nlevels = 4\n" + kObject,
        "s.toml", ".");
    EXPECT_EQ(s.detect.method, Method::brute_force);
    EXPECT_EQ(s.detect.partition.max_depth, 7);
    EXPECT_EQ(s.detect.partition.leaf_size, 3);
    EXPECT_DOUBLE_EQ(s.detect.partition.looseness, 1.5);
    EXPECT_EQ(s.detect.partition.levels, 4);
    EXPECT_EQ(parse_scene("[detector]\nmethod = \"auto\"\n" + kObject, "s.toml", ".").detect.method, Method::automatic);
}

TEST(SimScene, ShippedScenesAndDefaultParse)
{
    const Scene d = default_scene();
    EXPECT_GE(d.objects.size(), 2u);
    const std::filesystem::path dir = std::filesystem::path(TETHASH_SOURCE_DIR) / "meshes" / "scenes";
    int count = 0;
    for (const auto& entry : std::filesystem::directory_iterator(dir)) {
        if (entry.path().extension() != ".toml") continue;
        EXPECT_NO_THROW(load_scene(entry.path().string())) << entry.path();
        ++count;
    }
    EXPECT_GE(count, 6);
    // The shipped default.toml is the embedded default.
    EXPECT_EQ(tethash::test::read_text(dir / "default.toml"), default_scene_text());
    const Scene pile = load_scene((dir / "pile.toml").string());
    EXPECT_GE(pile.objects.size(), 100u);
}

TEST(SimScene, MissingFileIsAnError)
{
    expect_error([&] { load_scene("/nonexistent/scene.toml"); }, {"/nonexistent/scene.toml"});
}

TEST(SimScene, DirectoryIsNamedAsSuch)
{
    const std::filesystem::path dir = std::filesystem::temp_directory_path() / "tethash_scene_dir_test";
    std::filesystem::create_directories(dir);
    expect_error([&] { load_scene(dir.string()); }, {"is a directory"});
    std::filesystem::remove_all(dir);
}

TEST(SimScene, UpAxisAndTimeStepFractions)
{
    // up = "y": gravity against y, the ground's normal along it; a gravity or normal given too wins; dt takes the
    // command line's fractions; bad values name the key and line.
    Scene s = parse_scene("up = \"y\"\ndt = \"1/240\"\n[ground]\n" + kObject, "s.toml", ".");
    EXPECT_EQ(s.gravity, Eigen::Vector3d(0, -9.81, 0));
    EXPECT_EQ(s.ground.normal, Eigen::Vector3d(0, 1, 0));
    EXPECT_DOUBLE_EQ(s.dt, 1.0 / 240);
    s = parse_scene("up = \"-x\"\ngravity = [0, 0, -1]\n[ground]\nnormal = [0, 0, 1]\n" + kObject, "s.toml", ".");
    EXPECT_EQ(s.gravity, Eigen::Vector3d(0, 0, -1));
    EXPECT_EQ(s.ground.normal, Eigen::Vector3d(0, 0, 1));
    s = parse_scene("up = \"-x\"\n" + kObject, "s.toml", ".");
    EXPECT_EQ(s.gravity, Eigen::Vector3d(9.81, 0, 0));
    const std::string bad_up = error_of("up = \"w\"\n" + kObject);
    EXPECT_NE(bad_up.find("s.toml:1"), std::string::npos) << bad_up;
    EXPECT_NE(bad_up.find("'up'"), std::string::npos) << bad_up;
    for (const char* dt : {"\"1/0\"", "\"fast\"", "\"-1/240\"", "\"0\""}) {
        const std::string e = error_of(std::string("dt = ") + dt + "\n" + kObject);
        EXPECT_NE(e.find("'dt'"), std::string::npos) << dt << ": " << e;
        EXPECT_NE(e.find("s.toml:1"), std::string::npos) << dt << ": " << e;
    }
}
