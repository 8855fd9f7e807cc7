// tethash simulate: runs, writes frames that meshio reads back finite, refuses bad scenes with status 2,
// stops a blow-up with status 1 and never writes a NaN frame.
#include "support.hpp"

#include <filesystem>

using namespace tethash::test;

namespace {

const char* kSmall = R"(dt = 2e-3
steps = 6
gravity = [0, 0, -9.81]
[ground]
height = 0.0
[output]
every = 2
[[object]]
generate = { shape = "box", resolution = 2, size = 0.5 }
translate = [0, 0, 0.3]
[[object]]
generate = { shape = "sphere", resolution = 2, size = 0.4 }
translate = [0.1, 0, 0.7]
)";

/// Every frame of `dir` read by meshio: prints "OK n" if all points and point data are finite.
std::string check_frames(const std::string& py, const std::filesystem::path& dir)
{
    const std::string script = "import meshio, numpy, glob, sys\n"
                               "files = sorted(glob.glob(sys.argv[1] + '/frame_*.vtu'))\n"
                               "ok = len(files) > 0\n"
                               "for f in files:\n"
                               "    m = meshio.read(f)\n"
                               "    ok = ok and numpy.isfinite(m.points).all() and len(m.cells_dict['tetra']) > 0\n"
                               "    for k, v in m.point_data.items(): ok = ok and numpy.isfinite(v).all()\n"
                               "print('OK' if ok else 'BAD', len(files))\n";
    write_text(dir / "check.py", script);
    return run_shell(py + " " + quote(dir / "check.py") + " " + quote(dir)).out;
}

} // namespace

TEST(CliSimulate, RunsASceneAndWritesReadableFrames)
{
    const auto dir = temp_dir();
    write_text(dir / "s.toml", kSmall);
    const auto r = run_tethash("simulate " + quote(dir / "s.toml") + " --out " + quote(dir / "out"));
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_NE(r.out.find("energy: start"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("detection"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("penetration depth"), std::string::npos) << r.out;
    EXPECT_TRUE(std::filesystem::exists(dir / "out" / "scene.pvd"));
    for (const char* f : {"frame_00000.vtu", "frame_00002.vtu", "frame_00004.vtu", "frame_00006.vtu"})
        EXPECT_TRUE(std::filesystem::exists(dir / "out" / f)) << f;
    EXPECT_NE(read_text(dir / "out" / "scene.pvd").find("frame_00006.vtu"), std::string::npos);
    TETHASH_SKIP_WITHOUT_PYTHON(py, "meshio numpy");
    EXPECT_EQ(check_frames(py, dir / "out"), "OK 4\n");
}

TEST(CliSimulate, OverridesFromTheCommandLine)
{
    const auto dir = temp_dir();
    write_text(dir / "s.toml", kSmall);
    const auto r = run_tethash("simulate " + quote(dir / "s.toml") + " --steps 3 --dt 1e-3 --integrator local_global --threads 1 --out " +
                               quote(dir / "out"));
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_NE(r.out.find("local_global"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("steps: 3 "), std::string::npos) << r.out;
}

TEST(CliSimulate, DefaultSceneRuns)
{
    const auto dir = temp_dir();
    const auto r = run_tethash("simulate --steps 2 --out " + quote(dir / "out"));
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_NE(r.out.find("<default scene>"), std::string::npos) << r.out;
    EXPECT_TRUE(std::filesystem::exists(dir / "out" / "frame_00000.vtu"));
}

TEST(CliSimulate, BadSceneKeysAndOptionsExit2)
{
    const auto dir = temp_dir();
    write_text(dir / "bad.toml", std::string(kSmall) + "colour = \"red\"\n");
    auto r = run_tethash("simulate " + quote(dir / "bad.toml") + " --out " + quote(dir / "out"));
    EXPECT_EQ(r.status, 2);
    EXPECT_NE(r.err.find("object[1].colour"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("bad.toml:14"), std::string::npos) << r.err;

    write_text(dir / "bad2.toml", "dt = [1]\n[[object]]\ngenerate = { shape = \"box\" }\n");
    r = run_tethash("simulate " + quote(dir / "bad2.toml"));
    EXPECT_EQ(r.status, 2);
    EXPECT_NE(r.err.find("bad2.toml:1"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("'dt'"), std::string::npos) << r.err;

    r = run_tethash("simulate --integrator rk4 --steps 1 --out " + quote(dir / "o"));
    EXPECT_EQ(r.status, 2);
    EXPECT_NE(r.err.find("rk4"), std::string::npos) << r.err;
    r = run_tethash("simulate --dt -1 --out " + quote(dir / "o"));
    EXPECT_EQ(r.status, 2);
    EXPECT_NE(r.err.find("--dt"), std::string::npos) << r.err;
    r = run_tethash("simulate " + quote(dir / "missing.toml"));
    EXPECT_EQ(r.status, 2);
    EXPECT_NE(r.err.find("missing.toml"), std::string::npos) << r.err;
}

TEST(CliSimulate, BlowUpStopsWithStatus1AndNoNaNFrame)
{
    const auto dir = temp_dir();
    write_text(dir / "s.toml", std::string(kSmall) + "\n");
    const auto r = run_tethash("simulate " + quote(dir / "s.toml") +
                               " --integrator symplectic_euler --dt 0.05 --steps 200 --out " + quote(dir / "out"));
    EXPECT_EQ(r.status, 1) << r.out << r.err;
    EXPECT_NE(r.err.find("stability limit"), std::string::npos) << r.err;   // the warning up front
    EXPECT_NE(r.err.find("blew up at step"), std::string::npos) << r.err;
    EXPECT_TRUE(std::filesystem::exists(dir / "out" / "scene.pvd"));
    TETHASH_SKIP_WITHOUT_PYTHON(py, "meshio numpy");
    EXPECT_EQ(check_frames(py, dir / "out").substr(0, 3), "OK ");
}
