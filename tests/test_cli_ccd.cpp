// `tethash ccd`: the report and its JSON keys on a small file of hand-made queries, the shared benchmark files
// when present, and every kind of bad input refused with file and line (exit status 2).
#include "support.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <regex>
#include <string>

using namespace tethash::test;
namespace fs = std::filesystem;

namespace {

/// Two vertex-face queries: the vertex through the triangle (0,0,0), (1,0,0), (0,1,0) (truth 1), and the vertex
/// passing beside it, 1/4 beyond the long edge (truth 0). Coordinates as rationals, one beyond 64 bits.
const char* kQueries = "1,4,1,4,1,1,1\n"
                       "0,1,0,1,0,1,1\n"
                       "1,1,0,1,0,1,1\n"
                       "0,1,1,1,0,1,1\n"
                       "1,4,1,4,-1,1,1\n"
                       "0,1,0,1,0,1,1\n"
                       "1,1,0,1,0,1,1\n"
                       "0,1,1,1,0,1,1\n"
                       "3,4,1,2,1,1,0\n"
                       "0,1,0,1,0,1,0\n"
                       "1,1,0,1,0,1,0\n"
                       "0,1,1,1,0,1,0\n"
                       "55340232221128654848,73786976294838206464,1,2,-1,1,0\n"
                       "0,1,0,1,0,1,0\n"
                       "1,1,0,1,0,1,0\n"
                       "0,1,1,1,0,1,0\n";

std::string json_value(const std::string& json, const std::string& key)
{
    std::smatch m;
    if (std::regex_search(json, m, std::regex("\"" + key + "\": ([-0-9.e]+)"))) return m[1];
    return "";
}

} // namespace

TEST(CliCcd, ReportsQueriesAndJsonKeys)
{
    const fs::path dir = temp_dir();
    write_text(dir / "q.csv", kQueries);
    const RunResult text = run_tethash("ccd " + quote(dir / "q.csv") + " --type vertex-face");
    ASSERT_EQ(text.status, 0) << text.err;
    EXPECT_NE(text.out.find("2 queries (1 colliding), 0 false negatives, 0 false positives"), std::string::npos)
        << text.out;
    const RunResult json =
        run_tethash("ccd " + quote(dir / "q.csv") + " " + quote(dir / "q.csv") + " --type vertex-face --json");
    ASSERT_EQ(json.status, 0) << json.err;
    EXPECT_EQ(json_value(json.out, "queries"), "4") << json.out;
    EXPECT_EQ(json_value(json.out, "false_negatives"), "0") << json.out;
    EXPECT_EQ(json_value(json.out, "false_positives"), "0") << json.out;
    const std::string ns = json_value(json.out, "ns_per_query");
    ASSERT_FALSE(ns.empty()) << json.out;
    EXPECT_GT(std::stod(ns), 0.0);
    // Read as edge-edge the same rows are other queries (their truth no longer holds): only the count is checked.
    const RunResult as_edges = run_tethash("ccd " + quote(dir / "q.csv") + " --type edge-edge --json");
    EXPECT_EQ(json_value(as_edges.out, "queries"), "2") << as_edges.out << as_edges.err;
}

TEST(CliCcd, SharedBenchmarkFilesHaveNoFalseNegative)
{
    const fs::path shared = fs::path(TETHASH_SHARED_CCD) / "unit-tests";
    if (!fs::exists(shared)) GTEST_SKIP() << "no ../shared/ccd";
    for (const std::string type : {"vertex-face", "edge-edge"}) {
        const RunResult r = run_tethash("ccd " + quote(shared / type / "data_0_0.csv") + " " +
                                        quote(shared / type / "data_0_1.csv") + " --type " + type + " --json");
        ASSERT_EQ(r.status, 0) << type << r.err;
        EXPECT_EQ(json_value(r.out, "queries"), type == "edge-edge" ? "74" : "250") << r.out;
        EXPECT_EQ(json_value(r.out, "false_negatives"), "0") << r.out;
    }
}

TEST(CliCcd, BadInputIsRefusedWithFileAndLine)
{
    const fs::path dir = temp_dir();
    const std::string good = kQueries;
    const auto refuse = [&](const std::string& name, const std::string& content, const std::string& args,
                            std::initializer_list<std::string> parts) {
        write_text(dir / name, content);
        const RunResult r = run_tethash("ccd " + quote(dir / name) + " " + args);
        expect_refused(r, parts);
        EXPECT_EQ(r.out, "") << name;
    };
    refuse("columns.csv", good + "1,2,3,4\n", "--type vertex-face", {"columns.csv:17:", "7 columns", "found 4"});
    refuse("number.csv", "1,4,1e3,4,1,1,1\n" + good.substr(14), "--type vertex-face",
           {"number.csv:1:", "column 3-4", "'1e3'"});
    refuse("rows.csv", good.substr(0, 14 * 5), "--type edge-edge", {"rows.csv:5:", "multiple of 8"});
    refuse("zero.csv", "1,4,1,4,1,0,1\n" + good.substr(14), "--type vertex-face",
           {"zero.csv:1:", "column 5-6", "zero denominator"});
    refuse("type.csv", good, "--type vertex-edge", {"--type", "vertex-face", "edge-edge", "vertex-edge"});
    const RunResult missing = run_tethash("ccd " + quote(dir / "absent.csv") + " --type edge-edge");
    expect_refused(missing, {"absent.csv"});
    const RunResult no_type = run_tethash("ccd " + quote(dir / "type.csv"));
    expect_refused(no_type, {"--type"});
    const RunResult tol = run_tethash("ccd " + quote(dir / "type.csv") + " --type edge-edge --tolerance -1");
    expect_refused(tol, {"--tolerance"});
}

TEST(CliCcd, HelpNamesTheFormatAndOptions)
{
    const RunResult r = run_tethash("ccd --help");
    EXPECT_EQ(r.status, 0);
    for (const std::string part : {"--type", "vertex-face", "edge-edge", "--json", "numerator", "ns_per_query"})
        EXPECT_NE(r.out.find(part), std::string::npos) << part << "\n" << r.out;
}
