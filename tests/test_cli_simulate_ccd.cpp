// tethash simulate --ccd-queries DIR: the continuous queries of the chosen steps, in the CCD benchmark's format, read
// back by `tethash ccd`; a step's file holds as many queries as `detect --continuous` counts candidates between the
// step's two frames, and as many colliding as it finds contacts; the cap leaves out whole steps; bad options exit 2,
// a folder that takes no files exits 1, leaving nothing.
#include "support.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <regex>
#include <string>

using namespace tethash::test;
namespace fs = std::filesystem;

namespace {

// A box and a sphere overlapping from the start (boundary pairs of both objects and of each), a frame every step.
const char* kScene = R"(dt = 2e-3
steps = 4
[ground]
height = 0.0
[output]
every = 1
[[object]]
generate = { shape = "box", resolution = 2, size = 0.5 }
translate = [0, 0, 0.3]
[[object]]
generate = { shape = "sphere", resolution = 2, size = 0.4 }
translate = [0.1, 0, 0.7]
)";

/// The integer after `key` (a JSON member or a line's words), -1 if absent.
long long number_after(const std::string& text, const std::string& pattern)
{
    std::smatch m;
    if (!std::regex_search(text, m, std::regex(pattern))) return -1;
    return std::stoll(m[1].str());
}

struct Replay {
    long long queries = -1, colliding = -1;
};

Replay replay(const fs::path& file, const char* type)
{
    const RunResult r = run_tethash("ccd " + quote(file) + " --type " + type + " --json");
    EXPECT_EQ(r.status, 0) << r.err;
    return {number_after(r.out, "\"queries\": ([0-9]+)"), number_after(r.out, "\"colliding\": ([0-9]+)")};
}

} // namespace

TEST(CliSimulateCcd, WritesEachStepsQueriesThatTethashCcdReplays)
{
    const fs::path dir = temp_dir();
    write_text(dir / "s.toml", kScene);
    long long vf_sum = 0, ee_sum = 0;
    for (int step : {3, 4}) {
        const fs::path q = dir / ("q" + std::to_string(step));
        const RunResult r = run_tethash("simulate " + quote(dir / "s.toml") + " -o " + quote(dir / "out") +
                                        " --ccd-queries " + quote(q) + " --ccd-steps " + std::to_string(step));
        ASSERT_EQ(r.status, 0) << r.err;
        EXPECT_NE(r.out.find("ccd queries: "), std::string::npos) << r.out;
        // The step goes from frame step - 1 to frame step: continuous detection between them sees the same pairs.
        const auto frame = [&](int k) { return quote(dir / "out" / ("frame_0000" + std::to_string(k) + ".vtu")); };
        const RunResult d = run_tethash("detect --continuous " + frame(step - 1) + " " + frame(step));
        ASSERT_EQ(d.status, 0) << d.err;
        const long long vf = number_after(d.out, "continuous: ([0-9]+) vertex-face");
        const long long ee = number_after(d.out, "and ([0-9]+) edge-edge candidates");
        long long vf_hits = number_after(d.out, "\\(([0-9]+) vertex-face, [0-9]+ edge-edge\\)");
        long long ee_hits = number_after(d.out, "\\([0-9]+ vertex-face, ([0-9]+) edge-edge\\)");
        if (d.out.find("contacts: 0") != std::string::npos) vf_hits = ee_hits = 0;
        ASSERT_GT(vf, 0) << d.out;
        ASSERT_GT(ee, 0) << d.out;
        const Replay rvf = replay(q / "vertex_face.csv", "vertex-face");
        const Replay ree = replay(q / "edge_edge.csv", "edge-edge");
        EXPECT_EQ(rvf.queries, vf) << "step " << step;
        EXPECT_EQ(ree.queries, ee) << "step " << step;
        EXPECT_EQ(rvf.colliding, vf_hits) << "step " << step << ": the truth column is the narrow phase's answer";
        EXPECT_EQ(ree.colliding, ee_hits) << "step " << step;
        vf_sum += vf;
        ee_sum += ee;
    }
    // Both steps in one run; a cap below step 3's count leaves out both steps, with a note.
    const RunResult both = run_tethash("simulate " + quote(dir / "s.toml") + " -o " + quote(dir / "out") +
                                       " --ccd-queries " + quote(dir / "q34") + " --ccd-steps 3:4");
    ASSERT_EQ(both.status, 0) << both.err;
    EXPECT_EQ(replay(dir / "q34" / "vertex_face.csv", "vertex-face").queries, vf_sum);
    EXPECT_EQ(replay(dir / "q34" / "edge_edge.csv", "edge-edge").queries, ee_sum);
    const RunResult capped =
        run_tethash("simulate " + quote(dir / "s.toml") + " -o " + quote(dir / "out") + " --ccd-queries " +
                    quote(dir / "qc") + " --ccd-steps 3:4 --ccd-max-queries " + "1");
    ASSERT_EQ(capped.status, 0) << capped.err;
    EXPECT_NE(capped.err.find("step 3 and later left out"), std::string::npos) << capped.err;
    EXPECT_EQ(replay(dir / "qc" / "edge_edge.csv", "edge-edge").queries, 0);
}

TEST(CliSimulateCcd, BadOptionsExit2AndAFolderThatTakesNoFilesExits1)
{
    const fs::path dir = temp_dir();
    write_text(dir / "s.toml", kScene);
    const std::string base = "simulate " + quote(dir / "s.toml") + " -o " + quote(dir / "out") + " ";
    const auto refused = [&](const std::string& args, int status, const std::string& says) {
        const RunResult r = run_tethash(base + args);
        EXPECT_EQ(r.status, status) << args << "\n" << r.err;
        EXPECT_NE(r.err.find(says), std::string::npos) << args << "\n" << r.err;
    };
    refused("--ccd-queries " + quote(dir / "q") + " --ccd-steps 0", 2, "--ccd-steps");
    refused("--ccd-queries " + quote(dir / "q") + " --ccd-steps 4:3", 2, "--ccd-steps");
    refused("--ccd-queries " + quote(dir / "q") + " --ccd-steps x", 2, "--ccd-steps");
    refused("--ccd-queries " + quote(dir / "q") + " --ccd-max-queries 0", 2, "--ccd-max-queries");
    refused("--ccd-steps 2", 2, "--ccd-queries");
    refused("--ccd-queries " + quote(dir / "s.toml"), 2, "--ccd-queries");
    refused("--ccd-queries /proc", 1, "/proc");
    refused("--ccd-queries /proc/tethash_ccd", 1, "/proc");
    EXPECT_FALSE(fs::exists(dir / "q" / "vertex_face.csv"));
    EXPECT_FALSE(fs::exists(dir / "out")) << "refused before the run";
}
