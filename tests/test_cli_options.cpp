// Options that mean one thing in every command: --threads (bounded, 0 = every hardware thread), --cell-size
// (L a length, xF a factor of the mean edge), --table-size (N, xF, auto), outputs (-o/--out), and options placed
// before the positional arguments.
#include "../src/core/hash/table_size.hpp"
#include "support.hpp"

#include "tethash/detect.hpp"
#include "tethash/detect_grammar.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <sstream>
#include <string>
#include <vector>

using namespace tethash::test;
namespace fs = std::filesystem;

namespace {

const fs::path kBox = fs::path(TETHASH_SOURCE_DIR) / "meshes" / "box.vtu";

/// The value of "key": in a flat JSON text, as written (number or string without quotes).
std::string json_value(const std::string& json, const std::string& key)
{
    const auto k = json.find("\"" + key + "\": ");
    if (k == std::string::npos) return "";
    auto b = k + key.size() + 4;
    if (json[b] == '"') ++b;
    const auto e = json.find_first_of(",\n\"}", b);
    return json.substr(b, e - b);
}

} // namespace

TEST(CliOptions, ThreadsAboveTheLimitAreABadInputInEveryCommand)
{
    const auto dir = temp_dir();
    const std::vector<std::string> commands = {
        "detect " + quote(kBox),
        "simulate --steps 1 --out " + quote(dir / "sim"),
        "study threads --mesh " + quote(kBox) + " --no-plot --quiet --repeat 1 --out " + quote(dir / "study"),
    };
    for (const std::string count : {"65536", "40000", "-1", "two"})
        for (const std::string& c : commands) {
            const auto r = run_tethash(c + " --threads " + count);
            EXPECT_EQ(r.status, 2) << c << " --threads " << count << "\n" << r.err;
            EXPECT_NE(r.err.find("--threads"), std::string::npos) << r.err;
            EXPECT_EQ(r.err.find('\n'), r.err.size() - 1) << "one line: " << r.err;
            EXPECT_FALSE(fs::exists(dir / "study" / "study.csv.partial"));
            EXPECT_FALSE(fs::exists(dir / "study" / "study.csv"));
            EXPECT_FALSE(fs::exists(dir / "sim" / "frame_00000.vtu"));
        }
    const auto r = run_tethash("detect " + quote(kBox) + " --threads 65536");
    EXPECT_NE(r.err.find(std::to_string(tethash::max_threads())), std::string::npos) << r.err; // says the limit
}

TEST(CliOptions, ThreadsZeroMeansEveryHardwareThreadInEveryCommand)
{
    const auto dir = temp_dir();
    const auto d = run_tethash("detect " + quote(kBox) + " --threads 0");
    EXPECT_EQ(d.status, 0) << d.err;
    const auto s = run_tethash("simulate --steps 1 --threads 0 --out " + quote(dir / "sim"));
    EXPECT_EQ(s.status, 0) << s.err;
    const auto st = run_tethash("study cell-size --mesh " + quote(kBox) +
                                " --threads 0 --cell-size x1 --repeat 1 "
                                "--no-plot --quiet --no-oracle --no-penetration --out " +
                                quote(dir / "study"));
    EXPECT_EQ(st.status, 0) << st.err;
}

TEST(CliOptions, CellSizeIsALengthOrAFactorTheSameInDetectAndStudy)
{
    const auto dir = temp_dir();
    // detect: 0.5 is a length, x0.5 half the mean edge.
    ASSERT_EQ(run_tethash("detect " + quote(kBox) + " --cell-size 0.5 --stats " + quote(dir / "l.json")).status, 0);
    EXPECT_EQ(json_value(read_text(dir / "l.json"), "cell_size"), "0.5");
    ASSERT_EQ(run_tethash("detect " + quote(kBox) + " --cell-size x1 --stats " + quote(dir / "f1.json")).status, 0);
    ASSERT_EQ(run_tethash("detect " + quote(kBox) + " --cell-size x0.5 --stats " + quote(dir / "f.json")).status, 0);
    const double mean = std::stod(json_value(read_text(dir / "f1.json"), "cell_size"));
    EXPECT_NEAR(std::stod(json_value(read_text(dir / "f.json"), "cell_size")), 0.5 * mean, 1e-12 * mean);
    // study: the same two values give the same two cell sizes.
    const auto r = run_tethash(
        "study cell-size --mesh " + quote(kBox) +
        " --cell-size 0.5,x0.5 --repeat 1 --no-plot --quiet --no-oracle --no-penetration --out " + quote(dir / "s"));
    ASSERT_EQ(r.status, 0) << r.err;
    const std::string csv = read_text(dir / "s" / "study.csv");
    std::istringstream lines(csv);
    std::string header, row;
    std::getline(lines, header);
    std::vector<std::string> cols;
    {
        std::istringstream h(header);
        for (std::string c; std::getline(h, c, ',');)
            cols.push_back(c);
    }
    const auto col = std::find(cols.begin(), cols.end(), "cell_size") - cols.begin();
    std::vector<double> sizes;
    while (std::getline(lines, row)) {
        std::istringstream rr(row);
        std::string v;
        for (long i = 0; i <= col; ++i)
            std::getline(rr, v, ',');
        sizes.push_back(std::stod(v));
    }
    ASSERT_EQ(sizes.size(), 2u) << csv;
    std::sort(sizes.begin(), sizes.end());
    EXPECT_NEAR(sizes[0] + sizes[1], 0.5 + 0.5 * mean, 1e-9); // one is the length 0.5, the other half the mean edge
    EXPECT_TRUE(std::abs(sizes[0] - 0.5) < 1e-9 || std::abs(sizes[1] - 0.5) < 1e-9) << csv;
}

TEST(CliOptions, TableSizeFactorWorksInDetect)
{
    const auto dir = temp_dir();
    const auto r = run_tethash("detect " + quote(kBox) + " --table-size x2 --stats " + quote(dir / "s.json"));
    ASSERT_EQ(r.status, 0) << r.err;
    const std::string json = read_text(dir / "s.json");
    const long long vertices = std::stoll(json_value(json, "vertices"));
    EXPECT_EQ(std::stoll(json_value(json, "table_size")), tethash::next_power_of_two(2 * vertices)) << json;
    EXPECT_EQ(run_tethash("detect " + quote(kBox) + " --table-size x0").status, 2);
    EXPECT_EQ(run_tethash("detect " + quote(kBox) + " --table-size xabc").status, 2);
}

TEST(CliOptions, OptionsBeforeThePositionalArgumentsWork)
{
    const auto dir = temp_dir();
    const auto r = run_tethash("detect --static 0 " + quote(kBox) + " " + quote(kBox));
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_NE(r.out.find("scene: 2 objects"), std::string::npos) << r.out;
    const auto list = run_tethash("detect --static 0,1 --no-self " + quote(kBox) + " " + quote(kBox));
    ASSERT_EQ(list.status, 0) << list.err;
    EXPECT_NE(list.out.find("contacts: 0"), std::string::npos) << list.out; // both static: nothing to report
    const auto st = run_tethash("study --mesh " + quote(kBox) +
                                " --cell-size x1 cell-size --repeat 1 --no-plot --quiet "
                                "--no-oracle --no-penetration --out " +
                                quote(dir / "s"));
    EXPECT_EQ(st.status, 0) << st.err;
    // A value that is not one: the message names the option.
    const auto bad = run_tethash("detect --static " + quote(kBox) + " " + quote(kBox));
    expect_refused(bad, {"--static"});
}

TEST(CliOptions, EveryCommandWritesItsOutputWithDashOOrDashDashOut)
{
    const auto dir = temp_dir();
    EXPECT_EQ(run_tethash("convert " + quote(kBox) + " -o " + quote(dir / "a.mesh")).status, 0);
    EXPECT_TRUE(fs::exists(dir / "a.mesh"));
    EXPECT_EQ(run_tethash("convert " + quote(kBox) + " --out " + quote(dir / "b.vtk")).status, 0);
    EXPECT_TRUE(fs::exists(dir / "b.vtk"));
    EXPECT_EQ(run_tethash("convert " + quote(kBox) + " " + quote(dir / "c.msh")).status, 0); // the older form
    EXPECT_TRUE(fs::exists(dir / "c.msh"));
    const auto both =
        run_tethash("convert " + quote(kBox) + " " + quote(dir / "d.msh") + " -o " + quote(dir / "e.msh"));
    EXPECT_EQ(both.status, 2);
    EXPECT_FALSE(fs::exists(dir / "d.msh") || fs::exists(dir / "e.msh"));
    EXPECT_EQ(run_tethash("convert " + quote(kBox)).status, 2);
    EXPECT_EQ(run_tethash("generate sphere --resolution 3 --out " + quote(dir / "g.vtu")).status, 0);
    EXPECT_TRUE(fs::exists(dir / "g.vtu"));
    EXPECT_EQ(run_tethash("simulate --steps 1 -o " + quote(dir / "sim")).status, 0);
    EXPECT_TRUE(fs::exists(dir / "sim" / "scene.pvd"));
    EXPECT_EQ(run_tethash("study cell-size --mesh " + quote(kBox) +
                          " --cell-size x1 --repeat 1 --no-plot --quiet --no-oracle --no-penetration -o " +
                          quote(dir / "s"))
                  .status,
              0);
    EXPECT_TRUE(fs::exists(dir / "s" / "study.csv"));
}
