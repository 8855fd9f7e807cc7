// tethash study: the command end to end (CSV columns and rows, shards and merge, figures, bad input, Ctrl-C).
#include "study_support.hpp"
#include "support.hpp"

#include "tethash/io/mesh_io.hpp"
#include "tethash/meshing/generate.hpp"
#include "tethash/study/table.hpp"

#include <algorithm>
#include <chrono>
#include <map>
#include <thread>
#include <vector>

namespace tethash {
namespace {

using study::Table;
using test::quote;
using test::run_tethash;

/// Two overlapping boxes (study_support.hpp), quoted for the command line.
std::string two_boxes(const std::filesystem::path& dir, int resolution = 3)
{
    return quote(test::two_boxes(dir, resolution, Eigen::RowVector3d(0.31, 0.17, 0.23)));
}

using test::deterministic;

/// Columns the table of each sweep must have (among others).
const std::map<std::string, std::vector<const char*>> k_columns = {
    {"cell-size",
     {"point",
      "repeat",
      "scene",
      "cell_factor",
      "cell_size",
      "table_size",
      "hash",
      "threads",
      "vertices",
      "tets",
      "cells_visited",
      "entries_scanned",
      "hash_collisions",
      "box_rejections",
      "own_vertex_skips",
      "inside_tests",
      "exact_fallbacks",
      "degenerate_tets",
      "contacts",
      "table_load",
      "memory_bytes",
      "oracle_contacts",
      "missed",
      "extra",
      "ms_total",
      "ms_vertices",
      "ms_tets",
      "ms_inside",
      "ms_sort"}},
    {"integrator",
     {"integrator", "dt", "substeps", "status", "err_rms", "err_max", "max_penetration", "energy_drift",
      "wall_s_per_sim_s", "ref_dt"}},
    {"stability",
     {"integrator", "young", "dt", "mass_ratio", "verdict", "status", "inverted_fraction", "far_self", "ms_per_step",
      "size", "energy_growth", "volume_ratio", "unconverged_substeps", "problems"}},
};

/// Runs `tethash study SWEEP ARGS --out DIR/s`, which must succeed, and returns its DIR/s/study.csv, which must
/// have the sweep's columns (k_columns) and `rows` rows; an empty table after such a failure (reported).
/// `err`, when given, receives the run's standard error.
Table run_study(const std::string& sweep, const std::string& args, const std::filesystem::path& dir, std::size_t rows,
                std::string* err = nullptr)
{
    const auto r = run_tethash("study " + sweep + " " + args + " --out " + quote(dir / "s"));
    if (err) *err = r.err;
    EXPECT_EQ(r.status, 0) << r.err;
    if (r.status != 0) return {};
    Table t = Table::read_csv((dir / "s" / "study.csv").string());
    for (const char* col : k_columns.at(sweep)) {
        EXPECT_GE(t.index_of(col), 0) << col;
        if (t.index_of(col) < 0) return {};
    }
    EXPECT_EQ(t.rows.size(), rows);
    return t.rows.size() == rows ? t : Table{};
}

TEST(CliStudy, CellSizeSweepWritesEveryColumnAndRowExactAgainstOracle)
{
    const auto dir = test::temp_dir();
    const auto mesh = two_boxes(dir);
    std::string err;
    const Table t = run_study(
        "cell-size", "--mesh " + mesh + " --from 0.25 --to 4 --points 5 --table-size 1,x1 --repeat 2 --no-plot", dir,
        5u * 2 * 2, &err); // 5 cell sizes × 2 table sizes × 2 repeats
    for (const auto& row : t.rows) {
        EXPECT_EQ(row[t.index_of("missed")], "0");
        EXPECT_EQ(row[t.index_of("extra")], "0");
        EXPECT_EQ(row[t.index_of("contacts")], row[t.index_of("oracle_contacts")]);
    }
    const std::string json = test::read_text(dir / "s" / "study.json");
    EXPECT_NE(json.find("study cell-size"), std::string::npos);         // the command line is recorded
    EXPECT_NE(err.find("study: point 1/10"), std::string::npos) << err; // plain progress lines off a terminal
}

TEST(CliStudy, MergedShardsEqualTheUnshardedRun)
{
    const auto dir = test::temp_dir();
    const auto mesh = two_boxes(dir, 2);
    const std::string common = "study table-size --mesh " + mesh +
                               " --table-size x0.1:x10:3 --cell-size x0.7,x1.4 "
                               "--repeat 2 --no-plot --quiet";
    ASSERT_EQ(run_tethash(common + " --out " + quote(dir / "all")).status, 0);
    for (int i = 0; i < 3; ++i) {
        const auto r = run_tethash(common + " --shard " + std::to_string(i) + "/3 --out " +
                                   quote(dir / ("s" + std::to_string(i))));
        ASSERT_EQ(r.status, 0) << r.err;
    }
    const auto m = run_tethash("study merge " + quote(dir / "s2") + " " + quote(dir / "s0") + " " + quote(dir / "s1") +
                               " --no-plot --out " + quote(dir / "merged"));
    ASSERT_EQ(m.status, 0) << m.err;
    EXPECT_EQ(m.out.find("missing"), std::string::npos) << m.out;
    const Table all = Table::read_csv((dir / "all" / "study.csv").string());
    const Table merged = Table::read_csv((dir / "merged" / "study.csv").string());
    EXPECT_EQ(all.rows.size(), 3u * 2 * 2 * 2);
    EXPECT_EQ(deterministic(all).columns, deterministic(merged).columns);
    EXPECT_EQ(deterministic(all).rows, deterministic(merged).rows);

    // Two shards only: the merge says which points are missing.
    const auto part = run_tethash("study merge " + quote(dir / "s0") + " --no-plot --out " + quote(dir / "part"));
    EXPECT_EQ(part.status, 0);
    EXPECT_NE(part.out.find("missing"), std::string::npos) << part.out;
    // The same shard twice is an error.
    const auto twice = run_tethash("study merge " + quote(dir / "s0") + " " + quote(dir / "s0") + " --no-plot --out " +
                                   quote(dir / "twice"));
    expect_refused(twice, {"appears twice"});
}

TEST(CliStudy, PlotScriptWritesFiguresWhenMatplotlibIsPresent)
{
    TETHASH_SKIP_WITHOUT_PYTHON(py, "matplotlib");
    const auto dir = test::temp_dir();
    const auto mesh = two_boxes(dir, 2);
    const auto r = run_tethash("study cell-size --mesh " + mesh +
                               " --cell-size x0.5:x2:3 --table-size 31,x1 --repeat 1 --out " + quote(dir / "s"));
    ASSERT_EQ(r.status, 0) << r.err;
    for (const char* f : {"stages_vs_cell.png", "stages_vs_cell.svg", "candidates_vs_cell.svg", "exactness.svg"})
        EXPECT_TRUE(std::filesystem::exists(dir / "s" / f)) << f << "\n" << r.out << r.err;
    const std::string svg = test::read_text(dir / "s" / "stages_vs_cell.svg");
    EXPECT_NE(svg.find("cell size / mean edge length"), std::string::npos); // labelled axes
    EXPECT_NE(svg.find("command:"), std::string::npos);                     // the footer names the command
    // ... without the absolute paths of the machine that ran it (the mesh given as a path under the test folder).
    EXPECT_EQ(svg.find(dir.string()), std::string::npos) << "an absolute path in the footer";
    EXPECT_NE(svg.find("a.vtu+"), std::string::npos); // relative to the repository, or the file's name
    // The exactness figure's cell sizes on the log axis of the stages and candidates figures: ticks 0.5, 1, 2, not
    // the linear 0.50, 0.75, ..., 2.00 (nor 1.2, 1.4, ...).
    const std::string exact = test::read_text(dir / "s" / "exactness.svg");
    for (const char* tick : {">0.5</text>", ">1</text>", ">2</text>"})
        EXPECT_NE(exact.find(tick), std::string::npos) << tick;
    for (const char* tick : {">1.2</text>", ">1.25</text>", ">1.4</text>", ">1.5</text>", ">0.75</text>"})
        EXPECT_EQ(exact.find(tick), std::string::npos) << tick;
    // One page per study: well-formed (it parses as XML), the command and the machine, every figure it links there.
    test::write_text(dir / "check_report.py",
                     "import os, sys, xml.etree.ElementTree as ET\n"
                     "d = sys.argv[1]\n"
                     "root = ET.parse(os.path.join(d, 'report.html')).getroot()\n"
                     "text = ''.join(root.itertext())\n"
                     "links = [e.get('src') for e in root.iter('img')] + [e.get('href') for e in root.iter('a')]\n"
                     "missing = [l for l in links if not os.path.exists(os.path.join(d, l))]\n"
                     "print(len([e for e in root.iter('img')]), len(root.find('.//table').findall('.//tr')),\n"
                     "      'command:' in text and 'machine:' in text, missing)\n");
    const auto report = test::run_shell(py + " " + quote(dir / "check_report.py") + " " + quote(dir / "s"));
    EXPECT_EQ(report.status, 0) << report.err;
    // 5 figures (stages, candidates, exactness, table size, depth error), 6 points and the header, nothing missing.
    EXPECT_EQ(report.out, "5 7 True []\n") << report.out;

    const auto t = run_tethash("study table-size --mesh " + mesh + " --table-size x0.1:x10:3 --repeat 1 --out " +
                               quote(dir / "t"));
    ASSERT_EQ(t.status, 0) << t.err;
    EXPECT_TRUE(std::filesystem::exists(dir / "t" / "table_size.svg")) << t.out << t.err;
}

TEST(CliStudy, IntegratorSweepConvergesToTheReference)
{
    const auto dir = test::temp_dir();
    test::write_text(dir / "tiny.toml", R"(dt = 0.01
steps = 10
gravity = [0, 0, -9.81]
[[object]]
name = "cube"
generate = { shape = "box", resolution = 2, size = [0.2, 0.2, 0.2] }
translate = [0, 0, 0.5]
material = { density = 500, young = 1e4 }
)");
    const Table t = run_study("integrator",
                              "--scene " + quote(dir / "tiny.toml") +
                                  " --duration 0.04 --dt 0.0025,0.005,0.01 --integrator "
                                  "implicit_euler,symplectic_euler --reference-factor 4 --no-plot",
                              dir, 6);
    for (std::size_t i = 0; i < t.rows.size(); ++i) {
        const auto& row = t.rows[i];
        EXPECT_EQ(row[t.index_of("status")], "ok");
        EXPECT_DOUBLE_EQ(std::stod(row[t.index_of("ref_dt")]), 0.0025 / 4);
        if (i % 3 != 0) { // within one integrator: a larger dt gives a larger error (first-order methods)
            EXPECT_GT(std::stod(row[t.index_of("err_rms")]), std::stod(t.rows[i - 1][t.index_of("err_rms")])) << i;
        }
    }
}

TEST(CliStudy, StabilitySweepCellsFinishUncrumpledOrStopWithTheReason)
{
    // Two copies of a small box thrown into each other: every cell of the matrix either completes with at most
    // 1 % inverted tets ("ok"), completes with a problem its run's health names ("untrusted": energy gained, volume
    // lost, iterations unconverged), or stops with the simulator's message ("stopped", naming the step); "crumpled"
    // (completed but garbage) must never appear.
    const auto dir = test::temp_dir();
    meshing::GenerateParams p;
    p.shape = "box";
    p.resolution = 3;
    io::write_mesh((dir / "box.vtu").string(), meshing::generate(p));
    const Table t = run_study(
        "stability",
        "--mesh " + quote(dir / "box.vtu") +
            " --young 1e3,1e9 --dt 1/240,1/60 --mass-ratio 1,1e6 --integrator vbd,implicit_euler,symplectic_euler "
            "--duration 0.6 --no-plot --quiet",
        dir, 24);
    int ok = 0, stopped = 0;
    for (const auto& row : t.rows) {
        const std::string verdict = row[t.index_of("verdict")], status = row[t.index_of("status")];
        if (verdict == "ok") {
            ++ok;
            EXPECT_LE(std::stod(row[t.index_of("inverted_fraction")]), 0.01);
            EXPECT_EQ(row[t.index_of("problems")], "");
        } else if (verdict == "untrusted") {
            EXPECT_EQ(status, "ok");
            EXPECT_NE(row[t.index_of("problems")], "");
        } else {
            EXPECT_EQ(verdict, "stopped") << status;
            EXPECT_NE(status.find("step"), std::string::npos) << status;
            EXPECT_NE(status.find("likely cause"), std::string::npos) << status;
            ++stopped;
        }
    }
    // vbd completes the stiff equal-mass cells and can be trusted there at 1/240 (implicit Euler, linearised once a
    // step, gains energy at such impacts: untrusted); young 1e3 cannot carry a 1 m body's weight (ρ g h / E ≈ 10)
    // and must stop saying so.
    for (const auto& row : t.rows) {
        const std::string integ = row[t.index_of("integrator")], young = row[t.index_of("young")];
        if (integ == "vbd" && young == "1000000000" && row[t.index_of("dt")].substr(0, 5) == "0.004" &&
            row[t.index_of("mass_ratio")] == "1") {
            EXPECT_EQ(row[t.index_of("verdict")], "ok") << row[t.index_of("problems")];
        }
        if (young == "1000" && row[t.index_of("verdict")] == "stopped" &&
            row[t.index_of("status")].find("crumpled") != std::string::npos) {
            EXPECT_NE(row[t.index_of("status")].find("cannot carry its own weight"), std::string::npos);
        }
    }
    EXPECT_GE(ok, 2);
    EXPECT_GT(stopped, 0);
}

TEST(CliStudy, BadInputExitsTwoBeforeAnyWork)
{
    const auto dir = test::temp_dir();
    const auto mesh = two_boxes(dir, 2);
    const auto out = quote(dir / "out");
    const std::vector<std::pair<std::string, std::string>> cases = {
        {"study cell-size --mesh " + quote(dir / "missing.vtu"), "file not found"},
        {"study cell-size --mesh " + mesh + " --cell-size 0", "--cell-size"},
        {"study cell-size --mesh " + mesh + " --cell-size=-2", "--cell-size: expected a length"},
        {"study cell-size --mesh " + mesh + " --from 4 --to 1 --points 3", "empty range"},
        {"study cell-size --mesh " + mesh + " --cell-size x1:x2:0", "empty range"},
        {"study table-size --mesh " + mesh + " --table-size 0", "--table-size: expected N"},
        {"study cell-size --mesh " + mesh + " --shard 3/3", "--shard"},
        {"study cell-size --mesh " + mesh + " --shard x", "--shard"},
        {"study cell-size --mesh " + mesh + " --repeat 0", "--repeat"},
        {"study cell-size", "no scene"},
        {"study size --mesh " + mesh, "unknown sweep 'size'"},
        {"study merge " + quote(dir / "nothing"), "file not found"},
        {"study integrator --mesh " + mesh, "integrator sweep"},
        {"study integrator --dt 0", "--dt"},
        {"study integrator --scene " + quote(dir / "none.toml"), "file not found"},
        {"study stability", "give --mesh"},
        {"study stability --mesh " + quote(dir / "a.vtu") + " --mass-ratio 0", "--mass-ratio"},
        {"study stability --mesh " + quote(dir / "a.vtu") + " --dt 1/0", "--dt"},
    };
    for (const auto& [args, message] : cases) {
        const auto r = run_tethash(args + " --out " + out + " --no-plot");
        EXPECT_EQ(r.status, 2) << args << "\n" << r.err;
        EXPECT_NE(r.err.find(message), std::string::npos) << args << "\n" << r.err;
        EXPECT_FALSE(std::filesystem::exists(dir / "out" / "study.csv")) << args;
    }
}

TEST(CliStudy, InterruptKeepsTheRowsMeasuredInAValidCsv)
{
    const auto dir = test::temp_dir();
    const auto mesh = two_boxes(dir, 3);
    const auto csv = dir / "s" / "study.csv";
    // A long sweep in the background; SIGINT once a few rows are there.
    const std::string cmd = std::string("'") + TETHASH_EXE + "' study cell-size --mesh " + mesh +
                            " --cell-size x0.5:x2:400 --repeat 20 --no-oracle --no-penetration --no-plot --out " +
                            quote(dir / "s") + " >/dev/null 2>&1 & echo $! > " + quote(dir / "pid");
    ASSERT_EQ(std::system(cmd.c_str()), 0);
    const auto partial = dir / "s" / "study.csv.partial"; // rows are streamed there while the study runs
    bool rows = false;
    for (int i = 0; i < 600 && !rows; ++i) {
        std::this_thread::sleep_for(std::chrono::milliseconds(50));
        const std::string text = std::filesystem::exists(partial) ? test::read_text(partial) : std::string();
        rows = std::count(text.begin(), text.end(), '\n') > 3;
    }
    ASSERT_TRUE(rows);
    const std::string pid = test::read_text(dir / "pid");
    ASSERT_EQ(std::system(("kill -INT " + pid).c_str()), 0);
    bool finished = false;
    for (int i = 0; i < 600 && !finished; ++i) {
        std::this_thread::sleep_for(std::chrono::milliseconds(50));
        finished = test::read_text(dir / "s" / "study.json").find("\"interrupted\": true") != std::string::npos;
    }
    ASSERT_TRUE(finished);
    const Table t = Table::read_csv(csv.string()); // throws on a torn row
    EXPECT_FALSE(std::filesystem::exists(partial));
    EXPECT_GT(t.rows.size(), 2u);
    EXPECT_LT(t.rows.size(), 400u * 20);
}

} // namespace
} // namespace tethash
