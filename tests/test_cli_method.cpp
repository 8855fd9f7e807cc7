// `tethash detect --method`: every broad phase gives the default's contacts, `--method all` compares them in one
// table and says whether they agree, bad method and partition options are refused naming the option;
// `tethash study method`: a row per scene, method and partition value, the same contacts from every method.
#include "cli_support.hpp"
#include "core_scenes.hpp"
#include "study_support.hpp"
#include "support.hpp"
#include "tethash/detect.hpp"
#include "tethash/study/methods.hpp"
#include "tethash/study/table.hpp"

#include <map>
#include <set>

#include <gtest/gtest.h>

#include <sstream>

using namespace tethash;
using namespace tethash::test;

namespace {

/// Two overlapping lattice objects, one file each.
std::string two_objects(const std::filesystem::path& dir)
{
    const Scene a = lattice_object(3, 3, 3, 0.25, Eigen::Vector3d(0, 0, 0));
    const Scene b = lattice_object(3, 3, 3, 0.25, Eigen::Vector3d(0.125, 0.125, 0.3));
    write_text(dir / "a.mesh", medit_text(a));
    write_text(dir / "b.mesh", medit_text(b));
    return quote(dir / "a.mesh") + " " + quote(dir / "b.mesh");
}

bool not_built(const RunResult& r)
{
    return r.status == 2 && r.err.find("is not built yet") != std::string::npos;
}

} // namespace

TEST(CliMethod, EveryMethodWritesTheDefaultsContactsCsv)
{
    const auto dir = temp_dir();
    const std::string scene = two_objects(dir);
    const auto def = run_tethash("detect " + scene + " --threads 1 --contacts " + quote(dir / "default.csv"));
    ASSERT_EQ(def.status, 0) << def.err;
    const std::string want = read_text(dir / "default.csv");
    ASSERT_GT(csv_rows(want).size(), 10u) << "the scene should have contacts";
    int compared = 0;
    for (Method m : all_methods()) {
        const std::string name = to_string(m);
        const auto path = dir / (name + ".csv");
        const auto r = run_tethash("detect " + scene + " --threads 1 --method " + name + " --contacts " + quote(path));
        if (not_built(r)) continue; // a method still to come
        ASSERT_EQ(r.status, 0) << name << ": " << r.err;
        EXPECT_NE(r.out.find("broad phase: " + name), std::string::npos) << r.out;
        EXPECT_EQ(read_text(path), want) << name;
        ++compared;
    }
    EXPECT_GE(compared, 2) << "at least the hash and brute force run";
}

TEST(CliMethod, AllPrintsOneRowPerMethodAndTheAgreement)
{
    const auto dir = temp_dir();
    const auto r = run_tethash("detect " + two_objects(dir) + " --threads 1 --method all --repeat 1 --max-depth 6");
    ASSERT_EQ(r.status, 0) << r.err;
    std::istringstream in(r.out);
    std::vector<std::string> lines;
    for (std::string line; std::getline(in, line);)
        lines.push_back(line);
    const auto header =
        std::find_if(lines.begin(), lines.end(), [](const std::string& l) { return l.rfind("method ", 0) == 0; });
    ASSERT_NE(header, lines.end()) << r.out;
    for (const char* col :
         {"build ms", "query ms", "exact ms", "total ms", "candidates", "memory", "nodes", "contacts"})
        EXPECT_NE(header->find(col), std::string::npos) << col;
    int ran = 0;
    std::string contacts;
    for (Method m : all_methods()) {
        const std::string name = to_string(m);
        const auto row = std::find_if(header + 1, lines.end(), [&](const std::string& l) {
            return l.rfind(name + " ", 0) == 0 && l.find_first_not_of(' ', name.size()) != std::string::npos;
        });
        ASSERT_NE(row, lines.end()) << "no row for " << name << " in\n" << r.out;
        if (row->find("error:") != std::string::npos) continue;
        ++ran;
        const std::string last = row->substr(row->find_last_of(' ') + 1); // the contacts column
        if (contacts.empty()) contacts = last;
        EXPECT_EQ(last, contacts) << *row;
    }
    EXPECT_GE(ran, 2);
    EXPECT_NE(r.out.find("agreement: all " + std::to_string(ran) + " methods that ran returned the same " + contacts +
                         " contacts"),
              std::string::npos)
        << r.out;
}

TEST(CliMethod, BadMethodAndPartitionOptionsNameTheOption)
{
    const auto dir = temp_dir();
    const std::string scene = two_objects(dir);
    expect_refused(run_tethash("detect " + scene + " --method octtree"), {"--method", "octtree", "kd-point"});
    expect_refused(run_tethash("detect " + scene + " --max-depth 0"), {"--max-depth"});
    expect_refused(run_tethash("detect " + scene + " --max-depth 99"), {"--max-depth", "99"});
    expect_refused(run_tethash("detect " + scene + " --looseness 0.5"), {"--looseness", "0.5"});
    expect_refused(run_tethash("detect " + scene + " --leaf-size many"), {"--leaf-size", "many"});
    expect_refused(run_tethash("detect " + scene + " --levels 33"), {"--levels", "33"});
    expect_refused(run_tethash("detect " + scene + " --method all --contacts " + quote(dir / "c.csv")),
                   {"--contacts", "--method all"});
    EXPECT_FALSE(std::filesystem::exists(dir / "c.csv"));
}

TEST(CliMethod, StudyMethodRowPerSceneAndMethodWithTheSameContacts)
{
    const auto dir = temp_dir();
    std::filesystem::create_directories(dir / "one");
    std::filesystem::create_directories(dir / "two");
    const std::string one = two_boxes(dir / "one", 2, Eigen::RowVector3d(0.31, 0.17, 0.23));
    const std::string two = two_boxes(dir / "two", 3, Eigen::RowVector3d(0.2, 0.4, 0.1));
    const auto r =
        run_tethash("study method --mesh " + quote(one) + " --mesh " + quote(two) +
                    " --methods all --max-depth 4,8 --repeat 1 --warmup 0 --no-plot --quiet --out " + quote(dir / "s"));
    ASSERT_EQ(r.status, 0) << r.err;
    const study::Table t = study::Table::read_csv((dir / "s" / "study.csv").string());
    for (const char* col : {"scene", "method", "max_depth", "leaf_size", "looseness", "levels", "candidates", "nodes",
                            "memory_bytes", "contacts", "missed", "extra", "ms_total", "error"})
        ASSERT_GE(t.index_of(col), 0) << col;
    const auto at = [&](const study::Row& row, const char* col) {
        return row[static_cast<std::size_t>(t.index_of(col))];
    };
    std::map<std::string, std::multiset<std::string>> depths; // "scene method" -> its max_depth cells
    std::map<std::string, std::string> contacts;              // scene -> the contacts of every method that ran
    int ran = 0;
    for (const study::Row& row : t.rows) {
        ASSERT_EQ(at(row, "scene"), "a+b");
        depths[at(row, "vertices") + " " + at(row, "method")].insert(at(row, "max_depth"));
        if (!at(row, "error").empty()) continue;
        ++ran;
        EXPECT_EQ(at(row, "missed"), "0") << at(row, "scene") << " " << at(row, "method");
        EXPECT_EQ(at(row, "extra"), "0") << at(row, "scene") << " " << at(row, "method");
        auto [it, fresh] = contacts.emplace(at(row, "vertices"), at(row, "contacts"));
        EXPECT_EQ(at(row, "contacts"), it->second) << at(row, "vertices") << " " << at(row, "method");
    }
    EXPECT_GE(ran, 4) << "hash and brute force on both scenes";
    ASSERT_EQ(contacts.size(), 2u);
    for (const auto& [scene, count] : contacts)
        for (Method m : all_methods()) {
            const auto& cells = depths[scene + " " + to_string(m)];
            if (study::method_uses(m, "--max-depth"))
                EXPECT_EQ(cells, (std::multiset<std::string>{"4", "8"})) << to_string(m);
            else
                EXPECT_EQ(cells, (std::multiset<std::string>{""})) << to_string(m);
        }
    for (const auto& [args, message] :
         std::vector<std::pair<std::string, std::string>>{{"--methods octtree", "--methods"},
                                                          {"--max-depth 0", "--max-depth"},
                                                          {"--looseness 0.5", "--looseness"},
                                                          {"--partition-scenes nowhere", "--partition-scenes"}}) {
        const auto bad =
            run_tethash("study method --mesh " + quote(one) + " " + args + " --no-plot --out " + quote(dir / "bad"));
        expect_refused(bad, {message});
        EXPECT_FALSE(std::filesystem::exists(dir / "bad" / "study.csv")) << args;
    }
}

TEST(CliMethod, StudyMethodFigure)
{
    TETHASH_SKIP_WITHOUT_PYTHON(py, "matplotlib");
    const auto dir = temp_dir();
    const std::string mesh = two_boxes(dir, 2, Eigen::RowVector3d(0.31, 0.17, 0.23));
    const auto r = run_tethash("study method --mesh " + quote(mesh) + " --methods hash,brute --repeat 1 --out " +
                               quote(dir / "s"));
    ASSERT_EQ(r.status, 0) << r.err;
    ASSERT_TRUE(std::filesystem::exists(dir / "s" / "methods.svg")) << r.out << r.err;
    const std::string svg = read_text(dir / "s" / "methods.svg");
    for (const char* text : {"pairs tested (inside tests)", "brute", "command:"})
        EXPECT_NE(svg.find(text), std::string::npos) << text;
}
