// tethash simulate: runs, writes frames that meshio reads back finite, refuses bad scenes with status 2,
// stops a blow-up with status 1 and never writes a NaN frame.
#include "support.hpp"

#include <cstring>
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

// The shipped extreme scene (a projectile crossing the target in about a step, stiffness and mass ratios of 1e6,
// dt 0.02) runs to its end with nothing to report (--strict): a shipped scene that stops would greet a user with a
// failure. It used to stop at step 7, the target crumpled.
TEST(CliSimulate, ShippedExtremeSceneRunsToItsEnd)
{
    const auto dir = temp_dir();
    const auto scene = std::filesystem::path(TETHASH_SOURCE_DIR) / "meshes" / "scenes" / "extreme.toml";
    const auto r = run_tethash("simulate " + quote(scene) + " --strict --out " + quote(dir / "out"));
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_NE(r.err.find("step 50/50 "), std::string::npos) << r.err;
    EXPECT_NE(read_text(dir / "out" / "run.json").find("\"status\": \"ok\""), std::string::npos)
        << read_text(dir / "out" / "run.json");
    EXPECT_TRUE(std::filesystem::exists(dir / "out" / "frame_00050.vtu"));
}

TEST(CliSimulate, OverridesFromTheCommandLine)
{
    const auto dir = temp_dir();
    write_text(dir / "s.toml", kSmall);
    const auto r = run_tethash(
        "simulate " + quote(dir / "s.toml") +
        " --steps 3 --dt 1e-3 --integrator vbd --threads 1 --crossing-check on --continuous-check on --out " +
        quote(dir / "out"));
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_NE(r.out.find("vbd"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("steps: 3 "), std::string::npos) << r.out;
    EXPECT_NE(read_text(dir / "out" / "run.json").find("\"crossing_steps\": 0"), std::string::npos)
        << read_text(dir / "out" / "run.json");
    EXPECT_NE(read_text(dir / "out" / "run.json").find("\"continuous_unresolved_steps\": 0"), std::string::npos)
        << read_text(dir / "out" / "run.json");
}

TEST(CliSimulate, DefaultSceneRuns)
{
    // What tools/run shows: progress lines (stderr, not a terminal), the summary, frames meshio reads.
    const auto dir = temp_dir();
    const auto r = run_tethash("simulate --steps 10 --out " + quote(dir / "out"));
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_NE(r.out.find("<default scene>"), std::string::npos) << r.out;
    EXPECT_NE(r.err.find("step 1/10 "), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("step 10/10 "), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("steps/s"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("max pen"), std::string::npos) << r.err;
    for (const char* s : {"ms/step: detection ", ", response ", ", integration ", "contacts per step: ",
                          "penetration depth: max ", ", mean ", "energy: start ", ", end ", "scene.pvd"})
        EXPECT_NE(r.out.find(s), std::string::npos) << s << "\n" << r.out;
    // The summary's stages account for the whole step: they add up to its ms/step (to the printed rounding).
    {
        const size_t at = r.out.find("ms/step: detection ");
        ASSERT_NE(at, std::string::npos) << r.out;
        const size_t open = r.out.rfind('(', at);
        ASSERT_NE(open, std::string::npos);
        const double ms_step = std::stod(r.out.substr(open + 1));
        double sum = 0;
        int stages = 0;
        for (const char* stage :
             {"detection ", "depth ", "proximity ", "response ", "integration ", "checks ", "output and progress "}) {
            const size_t k = r.out.find(stage, at);
            ASSERT_NE(k, std::string::npos) << stage << "\n" << r.out;
            sum += std::stod(r.out.substr(k + std::strlen(stage)));
            ++stages;
        }
        EXPECT_EQ(stages, 7);
        EXPECT_NEAR(sum, ms_step, 0.005 + 0.0005 * stages) << r.out;
    }
    // A scene file's default thread count is every core, fewer in the steps where they do not pay: the summary
    // says how many steps ran at each count (all ten in all).
    if (r.out.find(" steps, up to ") != std::string::npos) {
        const size_t at = r.out.find("threads: ");
        ASSERT_NE(at, std::string::npos) << r.out;
        const size_t every = r.out.find("(every core) for ", at), one = r.out.find(", 1 for ", at);
        ASSERT_NE(every, std::string::npos) << r.out;
        ASSERT_NE(one, std::string::npos) << r.out;
        EXPECT_EQ(std::stoi(r.out.substr(every + 17)) + std::stoi(r.out.substr(one + 8)), 10) << r.out;
    }
    EXPECT_TRUE(std::filesystem::exists(dir / "out" / "frame_00000.vtu"));
    EXPECT_TRUE(std::filesystem::exists(dir / "out" / "frame_00010.vtu"));
    TETHASH_SKIP_WITHOUT_PYTHON(py, "meshio numpy");
    EXPECT_EQ(check_frames(py, dir / "out"), "OK 3\n");
}

TEST(CliSimulate, BadSceneKeysAndOptionsExit2)
{
    const auto dir = temp_dir();
    write_text(dir / "bad.toml", std::string(kSmall) + "colour = \"red\"\n");
    auto r = run_tethash("simulate " + quote(dir / "bad.toml") + " --out " + quote(dir / "out"));
    expect_refused(r, {"object[1].colour", "bad.toml:14"});

    write_text(dir / "bad2.toml", "dt = [1]\n[[object]]\ngenerate = { shape = \"box\" }\n");
    r = run_tethash("simulate " + quote(dir / "bad2.toml"));
    expect_refused(r, {"bad2.toml:1", "'dt'"});

    r = run_tethash("simulate --integrator rk4 --steps 1 --out " + quote(dir / "o"));
    expect_refused(r, {"rk4"});
    r = run_tethash("simulate --dt -1 --out " + quote(dir / "o"));
    expect_refused(r, {"--dt"});
    r = run_tethash("simulate --threads -1 --steps 1 --out " + quote(dir / "o"));
    expect_refused(r, {"--threads"});
    r = run_tethash("simulate " + quote(dir / "missing.toml"));
    expect_refused(r, {"missing.toml"});
    r = run_tethash("simulate --crossing-check yes --steps 1 --out " + quote(dir / "o"));
    expect_refused(r, {"--crossing-check", "on or off", "'yes'"});
    write_text(dir / "bad3.toml", "crossing_check = 1\n[[object]]\ngenerate = { shape = \"box\" }\n");
    r = run_tethash("simulate " + quote(dir / "bad3.toml") + " --steps 1 --out " + quote(dir / "o"));
    expect_refused(r, {"bad3.toml:1", "crossing_check"});
    r = run_tethash("simulate --continuous-check 1 --steps 1 --out " + quote(dir / "o"));
    expect_refused(r, {"--continuous-check", "on or off", "'1'"});
    write_text(dir / "bad4.toml", "continuous_check = \"on\"\n[[object]]\ngenerate = { shape = \"box\" }\n");
    r = run_tethash("simulate " + quote(dir / "bad4.toml") + " --steps 1 --out " + quote(dir / "o"));
    expect_refused(r, {"bad4.toml:1", "continuous_check"});
    r = run_tethash("simulate --contact-edges yes --steps 1 --out " + quote(dir / "o"));
    expect_refused(r, {"--contact-edges", "on or off", "'yes'"});
}

TEST(CliSimulate, BlowUpStopsWithStatus1AndNoNaNFrame)
{
    const auto dir = temp_dir();
    write_text(dir / "s.toml", std::string(kSmall) + "\n");
    const auto r = run_tethash("simulate " + quote(dir / "s.toml") +
                               " --integrator symplectic_euler --dt 0.05 --steps 200 --out " + quote(dir / "out"));
    EXPECT_EQ(r.status, 1) << r.out << r.err;
    EXPECT_NE(r.err.find("stability limit"), std::string::npos) << r.err; // the warning up front
    EXPECT_NE(r.err.find("blew up at step"), std::string::npos) << r.err;
    EXPECT_TRUE(std::filesystem::exists(dir / "out" / "scene.pvd"));
    TETHASH_SKIP_WITHOUT_PYTHON(py, "meshio numpy");
    EXPECT_EQ(check_frames(py, dir / "out").substr(0, 3), "OK ");
}

TEST(CliSimulate, ExplicitStabilityWarningIsPrintedUpFront)
{
    const auto dir = temp_dir();
    std::string text = kSmall; // the sphere above the box (they overlap in kSmall, which is warned about)
    text.replace(text.find("translate = [0.1, 0, 0.7]"), 25, "translate = [0.1, 0, 0.8]");
    write_text(dir / "s.toml", text);
    // dt above the limit: warned before the first step (the run itself survives one step).
    auto r = run_tethash("simulate " + quote(dir / "s.toml") +
                         " --integrator symplectic_euler --dt 0.002 --steps 1 --out " + quote(dir / "a"));
    ASSERT_EQ(r.status, 0) << r.err;
    const auto warn = r.err.find("warning: time step 0.002 s");
    ASSERT_NE(warn, std::string::npos) << r.err;
    EXPECT_NE(r.err.find("exceeds the explicit stability limit"), std::string::npos) << r.err;
    const auto first_step = r.err.find("step 1/1");
    ASSERT_NE(first_step, std::string::npos) << r.err;
    EXPECT_LT(warn, first_step) << r.err;
    // Below the limit, or with the implicit integrator: no warning.
    r = run_tethash("simulate " + quote(dir / "s.toml") + " --integrator symplectic_euler --dt 1e-5 --steps 1 --out " +
                    quote(dir / "b"));
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_EQ(r.err.find("warning"), std::string::npos) << r.err;
    r = run_tethash("simulate " + quote(dir / "s.toml") + " --integrator implicit_euler --dt 0.002 --steps 1 --out " +
                    quote(dir / "c"));
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_EQ(r.err.find("warning"), std::string::npos) << r.err;
}

TEST(CliSimulate, BlowUpWithinSubstepsIsARunFailureNamingTheStep)
{
    // Diverges within the second step of 3 substeps (19× its explicit limit): must exit 1 (run failure) naming step and
    // substep, not 2 (a detector error about the grid), keep the frames written so far, and never write a NaN frame.
    const auto dir = temp_dir();
    std::string text = kSmall;
    text.replace(text.find("every = 2"), 9, "every = 1");
    write_text(dir / "s.toml", text);
    const auto r =
        run_tethash("simulate " + quote(dir / "s.toml") +
                    " --integrator symplectic_euler --dt 0.014 --substeps 3 --steps 100 --out " + quote(dir / "out"));
    EXPECT_EQ(r.status, 1) << r.out << r.err;
    EXPECT_NE(r.err.find("blew up at step "), std::string::npos) << r.err;
    EXPECT_NE(r.err.find(", substep "), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("likely cause"), std::string::npos) << r.err;
    EXPECT_EQ(r.err.find("grid"), std::string::npos) << r.err;
    EXPECT_TRUE(std::filesystem::exists(dir / "out" / "frame_00000.vtu"));
    EXPECT_TRUE(std::filesystem::exists(dir / "out" / "frame_00001.vtu"));
    const std::string pvd = read_text(dir / "out" / "scene.pvd");
    EXPECT_NE(pvd.find("frame_00001.vtu"), std::string::npos) << pvd;
    TETHASH_SKIP_WITHOUT_PYTHON(py, "meshio numpy");
    const std::string check = check_frames(py, dir / "out");
    EXPECT_EQ(check.substr(0, 3), "OK ") << check;
}

TEST(CliSimulate, TimeStepIsCheckedAndAcceptsFractions)
{
    const auto dir = temp_dir();
    write_text(dir / "s.toml", kSmall);
    for (const char* bad : {"nan", "inf", "0", "-1/240", "1/0", "fast", "1/"}) {
        const auto r =
            run_tethash("simulate " + quote(dir / "s.toml") + " --dt " + quote(bad) + " --out " + quote(dir / "out"));
        EXPECT_EQ(r.status, 2) << bad << ": " << r.err;
        EXPECT_NE(r.err.find("--dt"), std::string::npos) << bad << ": " << r.err;
        EXPECT_NE(r.err.find(bad), std::string::npos) << bad << ": " << r.err;
    }
    const auto r =
        run_tethash("simulate " + quote(dir / "s.toml") + " --dt 1/500 --steps 1 --out " + quote(dir / "out"));
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_NE(r.out.find("dt 0.002 s"), std::string::npos) << r.out;
}

TEST(CliSimulate, APreviousRunsFramesAreRemovedWithANote)
{
    // Ten frames from a first run, then a run of two steps into the same folder: ParaView's file group must see
    // only the second run. Files the command does not write stay.
    const auto dir = temp_dir();
    write_text(dir / "s.toml", kSmall);
    auto r = run_tethash("simulate " + quote(dir / "s.toml") + " --steps 20 --out " + quote(dir / "out"));
    ASSERT_EQ(r.status, 0) << r.err;
    ASSERT_TRUE(std::filesystem::exists(dir / "out" / "frame_00020.vtu"));
    write_text(dir / "out" / "notes.txt", "mine");
    write_text(dir / "out" / "frame_1.vtu", "not of the pattern");
    r = run_tethash("simulate " + quote(dir / "s.toml") + " --steps 2 --out " + quote(dir / "out"));
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_NE(r.err.find("removed 14 files of a previous run"), std::string::npos) << r.err; // + run.json, static.vtu
    int frames = 0;
    for (const auto& e : std::filesystem::directory_iterator(dir / "out"))
        frames += e.path().filename().string().rfind("frame_0", 0) == 0;
    EXPECT_EQ(frames, 2); // frame_00000 and frame_00002
    EXPECT_FALSE(std::filesystem::exists(dir / "out" / "frame_00020.vtu"));
    EXPECT_TRUE(std::filesystem::exists(dir / "out" / "notes.txt"));
    EXPECT_TRUE(std::filesystem::exists(dir / "out" / "frame_1.vtu"));
    EXPECT_EQ(read_text(dir / "out" / "scene.pvd").find("frame_00020"), std::string::npos);
}

TEST(CliSimulate, CtrlCStopsAfterTheStepAndSaysTheFramesAreValid)
{
    // Job control on, so that the background run does not start with SIGINT ignored.
    const auto dir = temp_dir();
    const std::string cmd = "set -m; " + quote(TETHASH_EXE) + " simulate --steps 100000000 --out " +
                            quote(dir / "out") + " >/dev/null 2>" + quote(dir / "err") +
                            " & p=$!; for i in $(seq 100); do [ -e " + quote(dir / "out" / "frame_00010.vtu") +
                            " ] && break; sleep 0.1; done; kill -INT $p; wait $p; echo $?";
    write_text(dir / "run.sh", cmd + "\n");
    const auto r = run_shell("bash " + quote(dir / "run.sh"));
    EXPECT_EQ(r.out, "130\n") << r.err;
    const std::string err = read_text(dir / "err");
    EXPECT_NE(err.find("interrupted after step"), std::string::npos) << err;
    EXPECT_NE(err.find("form a valid series"), std::string::npos) << err;
    const std::string pvd = read_text(dir / "out" / "scene.pvd");
    EXPECT_NE(pvd.find("</VTKFile>"), std::string::npos) << pvd;
    EXPECT_NE(pvd.find("frame_00010.vtu"), std::string::npos);
}

TEST(CliSimulate, CtrlCEndsALongStepWithinIt)
{
    // One step of 100,000 substeps takes minutes: Ctrl-C must end it within the step (rolled back to its start),
    // not after it, and the run says where it stopped.
    const auto dir = temp_dir();
    const std::string cmd = "set -m; " + quote(TETHASH_EXE) + " simulate --steps 2 --dt 0.1 --substeps 100000 --out " +
                            quote(dir / "out") + " >/dev/null 2>" + quote(dir / "err") +
                            " & p=$!; for i in $(seq 100); do [ -e " + quote(dir / "out" / "scene.pvd") +
                            " ] && break; sleep 0.1; done; sleep 0.5; s=$(date +%s%N); kill -INT $p; wait $p; c=$?; "
                            "e=$(date +%s%N); echo $c $(( (e - s) / 1000000 ))";
    write_text(dir / "run.sh", cmd + "\n");
    const auto r = run_shell("bash " + quote(dir / "run.sh"));
    ASSERT_EQ(r.out.substr(0, 4), "130 ") << r.out << r.err;
    EXPECT_LT(std::stoi(r.out.substr(4)), 5000) << "ms from Ctrl-C to the end: " << r.out;
    const std::string err = read_text(dir / "err");
    EXPECT_NE(err.find("interrupted after step 0 of 2"), std::string::npos) << err;
    EXPECT_NE(read_text(dir / "out" / "run.json").find("\"status\": \"interrupted\""), std::string::npos);
}

TEST(CliSimulate, SaysWhatCannotBeTrustedAndStrictMakesItAnError)
{
    // A box resting on the ground with at most one sweep a substep: its substeps stop unconverged. The run says so
    // in its warnings, its summary and run.json, exits 0; with --strict it exits 1.
    const auto dir = temp_dir();
    write_text(dir / "s.toml", R"(dt = "1/240"
steps = 20
max_iterations = 1
[ground]
[[object]]
generate = { shape = "box", resolution = 3, size = 0.2 }
translate = [0, 0, 0.1005]
)");
    auto r = run_tethash("simulate " + quote(dir / "s.toml") + " --out " + quote(dir / "out"));
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_NE(r.err.find("warning: "), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("substeps stopped at max_iterations unconverged"), std::string::npos) << r.err;
    EXPECT_NE(r.out.find("health: "), std::string::npos) << r.out;
    EXPECT_EQ(r.out.find("0 unconverged of"), std::string::npos) << r.out;
    const std::string json = read_text(dir / "out" / "run.json");
    EXPECT_NE(json.find("\"status\": \"untrusted\""), std::string::npos) << json;
    EXPECT_NE(json.find("unconverged"), std::string::npos) << json;
    r = run_tethash("simulate " + quote(dir / "s.toml") + " --strict --out " + quote(dir / "out"));
    EXPECT_EQ(r.status, 1) << r.err;
    EXPECT_NE(r.err.find("--strict"), std::string::npos) << r.err;
    // The same box left to converge: trusted, status 0 with --strict, no warning.
    std::string text = read_text(dir / "s.toml");
    text.replace(text.find("max_iterations = 1"), 18, "max_iterations = 100");
    write_text(dir / "t.toml", text);
    r = run_tethash("simulate " + quote(dir / "t.toml") + " --strict --out " + quote(dir / "out2"));
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_EQ(r.err.find("warning"), std::string::npos) << r.err;
    EXPECT_NE(read_text(dir / "out2" / "run.json").find("\"status\": \"ok\""), std::string::npos);
}

TEST(CliSimulate, SetUpNamesSizesThatLookWrongAndObjectsBelowTheGround)
{
    const auto dir = temp_dir();
    const auto run = [&](const std::string& object) {
        write_text(dir / "s.toml", "dt = \"1/240\"\nsteps = 1\n[ground]\n[[object]]\nname = \"thing\"\n" + object);
        return run_tethash("simulate " + quote(dir / "s.toml") + " --out " + quote(dir / "out"));
    };
    auto r =
        run("generate = { shape = \"sphere\", resolution = 2, size = 0.5 }\nscale = 100\ntranslate = [0, 0, 30]\n");
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_NE(r.err.find("'thing' is 50 m across: if its mesh is in millimetres, give it scale = 0.001"),
              std::string::npos)
        << r.err;
    EXPECT_NE(r.out.find("object sizes (longest extent): thing 50 m"), std::string::npos) << r.out;
    r = run("generate = { shape = \"sphere\", resolution = 2, size = 0.002 }\ntranslate = [0, 0, 0.01]\n");
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_NE(r.err.find("'thing' is 2 mm across: check its scale"), std::string::npos) << r.err;
    r = run("generate = { shape = \"sphere\", resolution = 2, size = 0.5 }\ntranslate = [0, 0, 0.1]\n");
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_NE(r.err.find("'thing' starts 0.15 m below the ground"), std::string::npos) << r.err;
    r = run("generate = { shape = \"sphere\", resolution = 2, size = 0.5 }\ntranslate = [0, 0, 1]\n");
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_EQ(r.err.find("warning"), std::string::npos) << r.err;
    // The explicit stability limit concerns symplectic_euler only.
    EXPECT_EQ(r.out.find("explicit stability limit"), std::string::npos) << r.out;
    r = run_tethash("simulate " + quote(dir / "s.toml") + " --integrator symplectic_euler --dt 1e-5 --out " +
                    quote(dir / "out"));
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_NE(r.out.find("explicit stability limit"), std::string::npos) << r.out;
}

TEST(CliSimulate, ATimeStepFarBeyondTheSceneIsRefused)
{
    // dt = 1e9 asked for a million sweeps a substep and ignored Ctrl-C: now it is refused up front with the scene's
    // own time scale; ten times that is the most accepted.
    const auto dir = temp_dir();
    auto r = run_tethash("simulate --dt 1e9 --out " + quote(dir / "out"));
    EXPECT_EQ(r.status, 2) << r.err;
    EXPECT_NE(r.err.find("dt 1e+09 s is far beyond what this scene can show"), std::string::npos) << r.err;
    EXPECT_FALSE(std::filesystem::exists(dir / "out" / "frame_00000.vtu"));
    r = run_tethash("simulate --dt 0.05 --steps 2 --out " + quote(dir / "out"));
    EXPECT_EQ(r.status, 0) << r.err;
}

TEST(CliSimulate, AMeshDropsOnTheGroundInOneLine)
{
    // `simulate --mesh FILE --scale S --up y`: the mesh (y up, in millimetres) dropped on the ground; the scene it
    // ran is written next to the frames and runs again as it is; a mesh given where a scene goes is recognised; the
    // template scene is a scene the loader reads.
    const auto dir = temp_dir();
    auto r = run_tethash("generate sphere --resolution 4 -o " + quote(dir / "ball.vtu"));
    ASSERT_EQ(r.status, 0) << r.err;
    // The generated ball is 1 unit across: as "millimetres" scaled by 0.1 it is 10 cm.
    r = run_tethash("simulate --mesh " + quote(dir / "ball.vtu") + " --scale 0.1 --up y --steps 24 --out " +
                    quote(dir / "out"));
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_NE(r.out.find("object sizes (longest extent): ball 0.1"), std::string::npos) << r.out;
    EXPECT_NE(r.err.find("scene.toml"), std::string::npos) << r.err;
    const std::string scene = read_text(dir / "out" / "scene.toml");
    EXPECT_NE(scene.find("up = \"y\""), std::string::npos) << scene;
    EXPECT_NE(scene.find("scale = 0.1"), std::string::npos) << scene;
    EXPECT_TRUE(std::filesystem::exists(dir / "out" / "frame_00024.vtu"));
    EXPECT_FALSE(std::filesystem::exists(dir / "out" / "frame_00001.vtu")); // 60 frames a second
    // Gravity along -y: the ball fell in y (it lands within the 0.1 s), not in z.
    TETHASH_SKIP_WITHOUT_PYTHON(py, "meshio numpy");
    write_text(dir / "fall.py",
               "import meshio, sys\n"
               "a = meshio.read(sys.argv[1]).points.mean(axis=0)\n"
               "b = meshio.read(sys.argv[2]).points.mean(axis=0)\n"
               "print('y' if a[1] - b[1] > 1e-2 and abs(a[2] - b[2]) < 0.1 * (a[1] - b[1]) else 'other', a - b)\n");
    const auto fall = run_shell(py + " " + quote(dir / "fall.py") + " " + quote(dir / "out" / "frame_00000.vtu") + " " +
                                quote(dir / "out" / "frame_00024.vtu"));
    EXPECT_EQ(fall.out.substr(0, 2), "y ") << fall.out << fall.err;
    // The written scene runs again as it is.
    r = run_tethash("simulate " + quote(dir / "out" / "scene.toml") + " --steps 4 --out " + quote(dir / "again"));
    EXPECT_EQ(r.status, 0) << r.err;
    // A mesh where the scene goes: recognised, dropped as --mesh does, with a note.
    r = run_tethash("simulate " + quote(dir / "ball.vtu") + " --steps 4 --out " + quote(dir / "positional"));
    EXPECT_EQ(r.status, 0) << r.err;
    EXPECT_NE(r.err.find("is a mesh, not a scene"), std::string::npos) << r.err;
    // The template is a scene (its mesh file aside): printed, then read with a generated shape in its place.
    r = run_tethash("simulate --template");
    ASSERT_EQ(r.status, 0) << r.err;
    std::string text = r.out;
    text.replace(text.find("mesh = \"body.msh\""), 17, "generate = { shape = \"sphere\", resolution = 3 }");
    write_text(dir / "template.toml", text);
    r = run_tethash("simulate " + quote(dir / "template.toml") + " --steps 2 --out " + quote(dir / "tpl"));
    EXPECT_EQ(r.status, 0) << r.err;
    // Options of the one-line path without it, and bad values: exit 2 naming them.
    expect_refused(run_tethash("simulate --scale 0.001 --out " + quote(dir / "x")), {"--scale"});
    expect_refused(run_tethash("simulate --mesh " + quote(dir / "ball.vtu") + " --up w --out " + quote(dir / "x")),
                   {"--up", "'w'"});
    expect_refused(run_tethash("simulate --mesh " + quote(dir / "none.vtu") + " --out " + quote(dir / "x")),
                   {"none.vtu"});
}

TEST(CliSimulate, FramesDefaultToSixtyASecondAndProgressSaysTheTimeLeft)
{
    // No [output]: a frame every round(1 / (60 dt)) steps (4 at 1/240), not every step; the progress lines say the
    // time elapsed and left.
    const auto dir = temp_dir();
    write_text(dir / "s.toml",
               "dt = \"1/240\"\nsteps = 8\n[[object]]\ngenerate = { shape = \"box\", resolution = 2 }\n");
    const auto r = run_tethash("simulate " + quote(dir / "s.toml") + " --out " + quote(dir / "out"));
    ASSERT_EQ(r.status, 0) << r.err;
    for (const char* f : {"frame_00000.vtu", "frame_00004.vtu", "frame_00008.vtu"})
        EXPECT_TRUE(std::filesystem::exists(dir / "out" / f)) << f;
    for (const char* f : {"frame_00001.vtu", "frame_00002.vtu", "frame_00007.vtu"})
        EXPECT_FALSE(std::filesystem::exists(dir / "out" / f)) << f;
    EXPECT_NE(r.err.find(" s elapsed, "), std::string::npos) << r.err;
    EXPECT_NE(r.err.find(" s left"), std::string::npos) << r.err;
}
