// Bad input to every command that reads or writes files (info, convert, generate, tetrahedralize,
// detect, study): one line on standard error naming the thing, exit status 2, no work done first,
// no half-written or temporary file left, an existing good file never destroyed. A write the file
// system refuses (a folder that takes no files, a full disk) is not bad input: one line, exit status 1,
// the same guarantees.
#include "support.hpp"

#include "tethash/io/surface.hpp"

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <csignal>
#include <filesystem>
#include <signal.h>
#include <string>
#include <thread>
#include <unistd.h>
#include <vector>

using namespace tethash::test;
namespace fs = std::filesystem;

namespace {

const fs::path kBox = fs::path(TETHASH_SOURCE_DIR) / "meshes" / "box.vtu";

/// Lines of `text` (a trailing newline does not start another line).
std::size_t line_count(const std::string& text)
{
    std::size_t n = 0;
    for (char c : text)
        n += c == '\n';
    return n + (!text.empty() && text.back() != '\n');
}

/// The error contract: status 2, exactly one line "tethash: error: ..." holding every fragment.
void expect_one_line_error(const RunResult& r, const std::string& args, const std::vector<std::string>& fragments)
{
    EXPECT_EQ(r.status, 2) << args << "\n" << r.err;
    EXPECT_EQ(line_count(r.err), 1u) << args << "\n" << r.err;
    EXPECT_EQ(r.err.rfind("tethash: error: ", 0), 0u) << args << "\n" << r.err;
    for (const auto& f : fragments)
        EXPECT_NE(r.err.find(f), std::string::npos) << args << ": no '" << f << "' in\n" << r.err;
}

/// A write the file system refused: status 1, exactly one line "tethash: failed: ..." holding every fragment.
void expect_one_line_write_failure(const RunResult& r, const std::string& args,
                                   const std::vector<std::string>& fragments)
{
    EXPECT_EQ(r.status, 1) << args << "\n" << r.err;
    EXPECT_EQ(line_count(r.err), 1u) << args << "\n" << r.err;
    EXPECT_EQ(r.err.rfind("tethash: failed: ", 0), 0u) << args << "\n" << r.err;
    for (const auto& f : fragments)
        EXPECT_NE(r.err.find(f), std::string::npos) << args << ": no '" << f << "' in\n" << r.err;
}

/// Names in `dir` that look like temporary files (hidden, .tmp, .partial).
std::vector<std::string> temporaries(const fs::path& dir)
{
    std::vector<std::string> out;
    for (const auto& e : fs::directory_iterator(dir)) {
        const std::string n = e.path().filename().string();
        if (n[0] == '.' || n.find(".tmp") != std::string::npos || n.find(".partial") != std::string::npos)
            out.push_back(n);
    }
    return out;
}

} // namespace

TEST(CliBadInput, UsageErrorsAreOneLineNamingTheOption)
{
    const auto dir = temp_dir();
    const std::vector<std::pair<std::string, std::string>> cases = {
        {"generate box -o " + quote(dir / "g.vtu") + " --resolution abc", "--resolution"},
        {"generate box -o " + quote(dir / "g.vtu") + " --size 1 2", "--size"},
        {"tetrahedralize x.obj -o " + quote(dir / "t.vtu") + " -r abc", "--resolution"},
        {"study cell-size --mesh " + quote(kBox) + " --repeat abc", "--repeat"},
        {"info --no-such-option " + quote(kBox), "--no-such-option"},
        {"convert " + quote(kBox), "OUT"},
        {"no-such-command", "no-such-command"},
    };
    for (const auto& [args, fragment] : cases) {
        const RunResult r = run_tethash(args);
        expect_one_line_error(r, args, {fragment, "--help"});
        EXPECT_TRUE(r.out.empty()) << args << "\n" << r.out;
    }
    expect_one_line_error(run_tethash("detect " + quote(kBox) + " --threads abc"), "--threads abc",
                          {"--threads", "abc"});
    // Options that contradict each other.
    const std::vector<std::pair<std::string, std::string>> conflicts = {
        {"generate box -o " + quote(dir / "g.vtu") + " --size 1 1 1 --scale 2", "--scale"},
        {"generate box --list -o " + quote(dir / "g.vtu"), "--list"},
        {"study cell-size --mesh " + quote(kBox) + " --scene x.toml --out " + quote(dir / "s"), "--scene"},
        {"study integrator --mesh " + quote(kBox) + " --out " + quote(dir / "s"), "--mesh"},
        {"study hash --mesh " + quote(kBox) + " --from 1 --to 2 --points 2 --out " + quote(dir / "s"), "--from"},
    };
    for (const auto& [args, fragment] : conflicts) {
        expect_one_line_error(run_tethash(args), args, {fragment});
        EXPECT_FALSE(fs::exists(dir / "g.vtu")) << args;
        EXPECT_FALSE(fs::exists(dir / "s")) << args;
    }
    const std::string too_fine = "generate box -o " + quote(dir / "g.vtu") + " --resolution 5000";
    expect_one_line_error(run_tethash(too_fine), too_fine, {"--resolution 5000", "at most 1000"});
    // Help still goes to standard output with status 0, names the program (not its path) and shows defaults.
    const RunResult help = run_tethash("detect --help");
    EXPECT_EQ(help.status, 0);
    EXPECT_NE(help.out.find("Usage: tethash detect"), std::string::npos) << help.out;
    EXPECT_NE(help.out.find("--cell-size TEXT=auto"), std::string::npos) << help.out;
    EXPECT_NE(help.out.find("--method TEXT=hash"), std::string::npos) << help.out;
}

TEST(CliBadInput, InputThatIsMissingADirectoryOrEmpty)
{
    const auto dir = temp_dir();
    fs::create_directories(dir / "folder.vtu");
    for (const char* ext : {".vtu", ".vtk", ".msh", ".mesh", ".veg", ".node"})
        write_text(dir / (std::string("empty") + ext), "");
    struct Case {
        std::string args;
        std::vector<std::string> fragments;
    };
    const std::vector<Case> cases = {
        {"info " + quote(dir / "missing.vtu"), {"missing.vtu", "no such file"}},
        {"info " + quote(dir / "folder.vtu"), {"folder.vtu", "directory"}},
        {"detect " + quote(dir / "missing.vtu"), {"missing.vtu", "no such file"}},
        {"detect " + quote(dir / "folder.vtu"), {"folder.vtu", "directory"}},
        {"convert " + quote(dir / "folder.vtu") + " " + quote(dir / "o.vtu"), {"folder.vtu", "directory"}},
        {"study cell-size --no-plot --out " + quote(dir / "s") + " --mesh " + quote(dir / "folder.vtu"),
         {"folder.vtu", "directory"}},
        {"study integrator --no-plot --out " + quote(dir / "s") + " --scene " + quote(dir / "folder.vtu"),
         {"--scene", "directory"}},
        {"tetrahedralize " + quote(dir / "missing.obj") + " -o " + quote(dir / "t.vtu"),
         {"missing.obj", "no such file"}},
        {"tetrahedralize " + quote(kBox) + " -o " + quote(dir / "t.vtu"), {"box.vtu", "tet mesh", "surface"}},
        {"info " + quote(dir / "empty.vtu"), {"empty.vtu", "end of file"}},
        {"info " + quote(dir / "empty.vtk"), {"empty.vtk"}},
        {"info " + quote(dir / "empty.msh"), {"empty.msh", "end of file"}},
        {"info " + quote(dir / "empty.mesh"), {"empty.mesh", "end of file"}},
        {"info " + quote(dir / "empty.veg"), {"empty.veg"}},
        {"info " + quote(dir / "empty.node"), {"empty"}},
        {"info " + quote(dir / "mesh.xyz"), {"mesh.xyz"}},
    };
    for (const Case& c : cases)
        expect_one_line_error(run_tethash(c.args), c.args, c.fragments);
}

TEST(CliBadInput, UnreadableFileNamesIt)
{
    if (::geteuid() == 0) GTEST_SKIP() << "running as root: permissions do not stop reading";
    const auto dir = temp_dir();
    fs::copy_file(kBox, dir / "locked.vtu");
    fs::permissions(dir / "locked.vtu", fs::perms::none);
    expect_one_line_error(run_tethash("info " + quote(dir / "locked.vtu")), "info locked.vtu",
                          {"locked.vtu", "cannot open"});
}

TEST(CliBadInput, BadOutputPathsFailBeforeAnyWork)
{
    const auto dir = temp_dir();
    fs::create_directories(dir / "folder");
    write_text(dir / "file", "a file, not a folder\n");
    struct Case {
        std::string args;
        std::vector<std::string> fragments;
        int status = 2; ///< 1: the file system refuses (a folder that takes no files)
    };
    std::vector<Case> cases;
    const std::vector<std::pair<std::string, std::string>> commands = {
        {"convert " + quote(kBox) + " ", ""},
        {"generate box -r 2 -o ", ""},
        {"detect " + quote(kBox) + " --contacts ", "--contacts"},
        {"detect " + quote(kBox) + " --stats ", "--stats"},
    };
    for (const auto& [prefix, option] : commands) {
        cases.push_back({prefix + quote(dir / "missing" / "out.vtu"), {"out.vtu", "folder", "does not exist"}});
        cases.push_back({prefix + quote(dir / "folder"), {"folder", "is a directory"}});
        cases.push_back({prefix + quote(dir / "file" / "out.vtu"), {"out.vtu", "is not a folder"}});
        cases.push_back({prefix + quote("/proc/out.vtu"), {"/proc", "cannot create"}, 1});
        if (!option.empty())
            for (std::size_t i = cases.size() - 4; i < cases.size(); ++i)
                cases[i].fragments.push_back(option);
    }
    cases.push_back({"convert " + quote(kBox) + " " + quote(dir / "out.xyz"), {"out.xyz", "unknown output format"}});
    cases.push_back({"generate box -o " + quote(dir / "out.xyz"), {"out.xyz", "unknown output format"}});
    cases.push_back({"generate box -o " + quote(dir / "folder"), {"folder", "is a directory"}});
    if (tethash::io::have_assimp())
        cases.push_back({"tetrahedralize " + quote(fs::path(TETHASH_SOURCE_DIR) / "meshes" / "surfaces" / "blob.obj") +
                             " -o " + quote(dir / "missing" / "t.vtu"),
                         {"t.vtu", "does not exist"}});
    for (const Case& c : cases) {
        const RunResult r = run_tethash(c.args);
        if (c.status == 1)
            expect_one_line_write_failure(r, c.args, c.fragments);
        else
            expect_one_line_error(r, c.args, c.fragments);
        EXPECT_TRUE(r.out.empty()) << "work was done before the output was checked: " << c.args << "\n" << r.out;
    }
    EXPECT_TRUE(temporaries(dir).empty());
    EXPECT_TRUE(fs::is_empty(dir / "folder"));
}

// A write that fails part way (file size limit: the same errors as a full disk) exits 1 naming the
// file (not 2: the input was good), leaves no temporary and keeps the file that was there.
TEST(CliBadInput, FailedWriteKeepsTheOldFileAndLeavesNoTemporary)
{
    const auto dir = temp_dir();
    std::vector<std::string> names = {"out.vtu", "out.vtk", "out.msh", "out.mesh", "out.node"};
    if (tethash::io::have_assimp()) names.insert(names.end(), {"out.obj", "out.ply", "out.stl", "out.gltf", "out.glb"});
    const std::string good = "a good file that must survive\n";
    for (const auto& name : names) {
        const fs::path out = dir / name;
        write_text(out, good);
        if (name == "out.node") write_text(dir / "out.ele", good);
        if (name == "out.gltf") write_text(dir / "out.bin", good);
        // dash counts ulimit -f in 512-byte blocks: 4 KiB, far less than any of these files.
        const RunResult r = run_shell("trap '' XFSZ; ulimit -f 8; " + quote(TETHASH_EXE) + " convert " + quote(kBox) +
                                      " " + quote(out));
        expect_one_line_write_failure(r, name, {name, "write failed"});
        EXPECT_EQ(r.err.find(".tmp"), std::string::npos) << "the message names the temporary: " << r.err;
        EXPECT_EQ(read_text(out), good) << name;
        if (name == "out.node") {
            EXPECT_EQ(read_text(dir / "out.ele"), good);
        }
        EXPECT_TRUE(temporaries(dir).empty()) << name << ": " << temporaries(dir).front();
    }
    // The same for detect's outputs (the contacts of two overlapping boxes fill more than 4 KiB).
    write_text(dir / "c.csv", good);
    ASSERT_EQ(run_tethash("generate box -r 6 -o " + quote(dir / "b.vtu")).status, 0);
    const RunResult r =
        run_shell("trap '' XFSZ; ulimit -f 8; " + quote(TETHASH_EXE) + " detect " + quote(dir / "b.vtu") + " " +
                  quote(dir / "b.vtu") + " --contacts " + quote(dir / "c.csv"));
    expect_one_line_write_failure(r, "detect --contacts", {"c.csv", "write failed"});
    EXPECT_EQ(read_text(dir / "c.csv"), good);
    EXPECT_TRUE(temporaries(dir).empty());
    fs::remove(dir / "c.csv");
    // Without the limit the same command writes the file: the failure above was the write.
    ASSERT_EQ(run_tethash("detect " + quote(dir / "b.vtu") + " " + quote(dir / "b.vtu") + " --contacts " +
                          quote(dir / "c.csv"))
                  .status,
              0);
    EXPECT_GT(fs::file_size(dir / "c.csv"), 4096u);
    // simulate: its first frame does not fit; no frame, no temporary, no run.json claiming a run.
    const RunResult sim =
        run_shell("trap '' XFSZ; ulimit -f 8; " + quote(TETHASH_EXE) + " simulate --steps 2 -o " + quote(dir / "run"));
    expect_one_line_write_failure(sim, "simulate -o run", {"frame_00000.vtu", "write failed"});
    EXPECT_TRUE(fs::is_empty(dir / "run"));
}

TEST(CliBadInput, StudyRejectsBadCountsAndOutputFolders)
{
    const auto dir = temp_dir();
    write_text(dir / "file", "not a folder\n");
    const std::string base = "study cell-size --no-plot --quiet --cell-size 1 --mesh " + quote(kBox);
    const std::vector<std::pair<std::string, std::string>> cases = {
        {base + " --repeat -2 --out " + quote(dir / "s"), "--repeat"},
        {base + " --warmup -1 --out " + quote(dir / "s"), "--warmup"},
        {base + " --out " + quote(dir / "file"), "not a folder"},
        {base + " --out " + quote(dir / "file" / "sub"), "--out"},
    };
    for (const auto& [args, fragment] : cases) {
        const RunResult r = run_tethash(args);
        expect_one_line_error(r, args, {fragment});
        EXPECT_TRUE(r.out.empty()) << args << "\n" << r.out;
    }
    // A folder that takes no files: the file system refuses, exit 1.
    const std::string proc = base + " --out /proc/tethash_study";
    const RunResult r = run_tethash(proc);
    expect_one_line_write_failure(r, proc, {"--out", "/proc"});
    EXPECT_TRUE(r.out.empty()) << proc << "\n" << r.out;
    EXPECT_FALSE(fs::exists(dir / "s" / "study.csv"));
    EXPECT_EQ(read_text(dir / "file"), "not a folder\n");
}

TEST(CliBadInput, PlotScriptRejectsWhatIsNotAStudyInOneLine)
{
    TETHASH_SKIP_WITHOUT_PYTHON(py, "matplotlib");
    const auto dir = temp_dir();
    const std::string script = quote(fs::path(TETHASH_SOURCE_DIR) / "tools" / "plot_study.py");
    fs::create_directories(dir / "other");
    write_text(dir / "other" / "study.csv", "a,b\n1,2\n");
    const std::vector<std::pair<std::string, std::string>> cases = {{quote(dir / "none"), "no such file"},
                                                                    {quote(dir / "other"), "not a tethash study"}};
    for (const auto& [arg, fragment] : cases) {
        const RunResult r = run_shell(py + " " + script + " " + arg);
        EXPECT_EQ(r.status, 2) << arg << "\n" << r.err;
        EXPECT_EQ(line_count(r.err), 1u) << r.err;
        EXPECT_NE(r.err.find(fragment), std::string::npos) << r.err;
        EXPECT_EQ(r.err.find("Traceback"), std::string::npos) << r.err;
    }
}

// Ctrl-C while a file is being written: the temporary goes, the old file stays. The signal has to land
// during the write; when the machine is too fast to catch the temporary, the test is skipped.
TEST(CliBadInput, InterruptedWriteLeavesNoTemporary)
{
    const auto dir = temp_dir();
    write_text(dir / "a.vtu", "good\n");
    // The shell writes its pid and becomes tethash (exec): that pid is the one to interrupt.
    const std::string cmd = "echo $$ > " + quote(dir / "pid") + "; exec " + quote(TETHASH_EXE) +
                            " generate box -r 40 -o " + quote(dir / "a.vtu") + " >/dev/null 2>&1";
    std::atomic<bool> done{false};
    std::thread run([&] {
        (void)std::system(cmd.c_str());
        done = true;
    });
    auto temporary_with_data = [&] {
        for (const auto& e : fs::directory_iterator(dir)) {
            std::error_code ec;
            if (e.path().filename().string().find(".tmp") != std::string::npos && fs::file_size(e.path(), ec) > 0 &&
                !ec)
                return true;
        }
        return false;
    };
    bool caught = false;
    while (!done && !caught) {
        if (temporary_with_data()) {
            const std::string pid = read_text(dir / "pid");
            caught = !pid.empty() && ::kill(std::stoi(pid), SIGINT) == 0;
        }
        std::this_thread::sleep_for(std::chrono::microseconds(200));
    }
    run.join();
    if (!caught) GTEST_SKIP() << "the write finished before the temporary file was seen";
    EXPECT_TRUE(temporaries(dir).empty()) << temporaries(dir).front();
    EXPECT_EQ(read_text(dir / "a.vtu"), "good\n");
}
