// The study library: value lists, CSV, a small detection sweep against the oracle, the Teschner scenarios.
#include "study_support.hpp"
#include "support.hpp"

#include "tethash/error.hpp"
#include "tethash/io/mesh_io.hpp"
#include "tethash/oracle.hpp"
#include "tethash/study/scenarios.hpp"
#include "tethash/study/study.hpp"
#include "tethash/study/table.hpp"

#include <cmath>
#include <set>

namespace tethash {
namespace {

using study::StudyOptions;
using study::Sweep;
using study::Table;
using test::expect_error;

/// Two overlapping boxes (study_support.hpp).
std::string two_boxes(const std::filesystem::path& dir, int resolution = 3)
{
    return test::two_boxes(dir, resolution, Eigen::RowVector3d(0.37, 0.21, 0.13));
}

std::string error_of(const StudyOptions& o)
{
    try {
        study::plan_study(o);
    } catch (const Error& e) {
        return e.what();
    }
    return "";
}

TEST(StudyPlan, BadInputIsRejectedWithTheOptionNamed)
{
    const auto dir = test::temp_dir();
    StudyOptions o;
    o.meshes = {two_boxes(dir)};
    o.out_dir = (dir / "out").string();

    auto with = [&](auto change) {
        StudyOptions c = o;
        change(c);
        return error_of(c);
    };
    EXPECT_NE(with([](StudyOptions& c) { c.cell_size = {"0"}; }).find("--cell-size"), std::string::npos);
    EXPECT_NE(with([](StudyOptions& c) { c.cell_size = {"-0.5"}; }).find("--cell-size: expected a length"),
              std::string::npos);
    EXPECT_NE(with([](StudyOptions& c) { c.cell_size = {"4:1:3"}; }).find("empty range"), std::string::npos);
    EXPECT_NE(with([](StudyOptions& c) { c.cell_size = {"1:4:0"}; }).find("empty range"), std::string::npos);
    EXPECT_NE(with([](StudyOptions& c) { c.cell_size = {"abc"}; }).find("--cell-size"), std::string::npos);
    EXPECT_NE(with([](StudyOptions& c) { c.table_size = {"0"}; }).find("--table-size"), std::string::npos);
    EXPECT_NE(with([](StudyOptions& c) { c.hash = {"md5"}; }).find("md5"), std::string::npos);
    EXPECT_NE(with([](StudyOptions& c) { c.threads = {"65536"}; }).find("--threads"), std::string::npos);
    EXPECT_NE(
        with([](StudyOptions& c) { c.meshes = {"/nonexistent/x.vtu"}; }).find("file not found: /nonexistent/x.vtu"),
        std::string::npos);
    EXPECT_NE(with([](StudyOptions& c) { c.meshes.clear(); }).find("no scene"), std::string::npos);
    EXPECT_NE(with([](StudyOptions& c) { c.repeat = 0; }).find("--repeat"), std::string::npos);
    EXPECT_NE(with([](StudyOptions& c) {
                  c.sweep = Sweep::grid;
                  c.grid = {"cell-size"};
              }).find("--grid"),
              std::string::npos);
    EXPECT_EQ(with([](StudyOptions&) {}), "");
    EXPECT_FALSE(std::filesystem::exists(dir / "out")); // planning does no work

    int i = 0, n = 0;
    EXPECT_THROW(study::parse_shard("2/2", i, n), Error);
    EXPECT_THROW(study::parse_shard("1", i, n), Error);
    EXPECT_THROW(study::parse_shard("a/b", i, n), Error);
    study::parse_shard("1/3", i, n);
    EXPECT_EQ(i, 1);
    EXPECT_EQ(n, 3);
}

TEST(StudyPlan, RangesGiveLogSpacedCellsAndPrimeAndPowerOfTwoTables)
{
    const auto dir = test::temp_dir();
    StudyOptions o;
    o.sweep = Sweep::table_size;
    o.meshes = {two_boxes(dir)};
    o.table_size = {"x0.5:x2:3"};
    auto plan = study::plan_study(o);
    ASSERT_EQ(study::points_total(*plan), 6); // 3 values × (power of two, prime)
    o.sweep = Sweep::cell_size;
    o.table_size.clear();
    o.cell_size = {"x0.25:x4:5", "x7"};
    plan = study::plan_study(o);
    EXPECT_EQ(study::points_total(*plan), 6);
    o.shard_index = 1;
    o.shard_count = 4;
    plan = study::plan_study(o);
    EXPECT_EQ(study::points_in_shard(*plan), 2); // points 1 and 5
}

TEST(StudyTable, CsvRoundTripsQuotedFields)
{
    const auto dir = test::temp_dir();
    Table t;
    t.columns = {"a", "b,c", "ms_x"};
    t.rows = {{"1", "say \"hi\"", "0.5"}, {"", "two\nlines", "3"}};
    t.write_csv((dir / "t.csv").string());
    const Table r = Table::read_csv((dir / "t.csv").string());
    EXPECT_EQ(r.columns, t.columns);
    EXPECT_EQ(r.rows, t.rows);
    EXPECT_TRUE(study::is_timing_column("ms_total"));
    EXPECT_TRUE(study::is_timing_column("wall_s_per_sim_s"));
    EXPECT_FALSE(study::is_timing_column("contacts"));
    test::write_text(dir / "bad.csv", "a,b\n1,2\n3\n");
    expect_error([&] { Table::read_csv((dir / "bad.csv").string()); }, {"bad.csv:3"});
}

TEST(StudyRun, SmallSweepMatchesTheOracleInEveryRow)
{
    const auto dir = test::temp_dir();
    StudyOptions o;
    o.sweep = Sweep::grid;
    o.grid = {"cell-size", "table-size"};
    o.meshes = {two_boxes(dir)};
    o.cell_size = {"x0.2,x1,x5"};
    o.table_size = {"1,2,97,x1"};
    o.threads = {"1,2"};
    o.repeat = 2;
    o.out_dir = (dir / "out").string();
    auto plan = study::plan_study(o);
    ASSERT_EQ(study::points_total(*plan), 3 * 4 * 2);
    const auto res = study::run_study(*plan);
    EXPECT_FALSE(res.interrupted);
    EXPECT_EQ(res.rows, 3 * 4 * 2 * 2);

    const Table t = Table::read_csv(res.csv_path);
    ASSERT_EQ(static_cast<std::int64_t>(t.rows.size()), res.rows);
    const int contacts = t.index_of("contacts"), oracle = t.index_of("oracle_contacts"), missed = t.index_of("missed"),
              extra = t.index_of("extra"), table = t.index_of("table_size");
    ASSERT_GE(contacts, 0);
    ASSERT_GE(oracle, 0);
    std::set<std::string> tables;
    for (const auto& r : t.rows) {
        EXPECT_EQ(r[static_cast<std::size_t>(missed)], "0");
        EXPECT_EQ(r[static_cast<std::size_t>(extra)], "0");
        EXPECT_EQ(r[static_cast<std::size_t>(contacts)], r[static_cast<std::size_t>(oracle)]);
        EXPECT_NE(r[static_cast<std::size_t>(contacts)], "0"); // the boxes overlap
        tables.insert(r[static_cast<std::size_t>(table)]);
    }
    EXPECT_TRUE(tables.count("1") && tables.count("2") && tables.count("97"));
    const std::string json = test::read_text(res.json_path);
    for (const char* key :
         {"\"machine\"", "\"cores\"", "\"cpu\"", "\"compiler\"", "\"summary\"", "\"median\"", "\"points_total\": 24"})
        EXPECT_NE(json.find(key), std::string::npos) << key;
}

TEST(StudyMerge, MergedShardsEqualTheUnshardedStudy)
{
    const auto dir = test::temp_dir();
    StudyOptions o;
    o.sweep = Sweep::grid;
    o.grid = {"cell-size", "hash"};
    o.meshes = {two_boxes(dir, 2)};
    o.cell_size = {"x0.5:x2:3"};
    o.repeat = 2;
    o.penetration = false;
    o.command_line = "study \"quoted\"\tcommand";
    o.out_dir = (dir / "all").string();
    const auto all = study::run_study(*study::plan_study(o));
    std::vector<std::string> shards;
    for (int n : {1, 2, 5}) { // one shard, two shards and more shards than points in one pass each
        shards.clear();
        for (int i = 0; i < n; ++i) {
            StudyOptions so = o;
            so.shard_index = i;
            so.shard_count = n;
            so.out_dir = (dir / (std::to_string(n) + "-shards") / std::to_string(i)).string();
            study::run_study(*study::plan_study(so));
            shards.insert(shards.begin(), so.out_dir); // reversed: the merge orders rows itself
        }
        const std::string out = (dir / ("merged" + std::to_string(n))).string();
        EXPECT_TRUE(study::merge_studies(shards, out, "merge").empty()) << n << " shards";
        const Table a = Table::read_csv(all.csv_path), m = Table::read_csv(out + "/study.csv");
        EXPECT_EQ(a.columns, m.columns);
        EXPECT_EQ(test::deterministic(a).rows, test::deterministic(m).rows) << n << " shards";
        const std::string json = test::read_text(out + "/study.json");
        EXPECT_NE(json.find("\"sweep\": \"grid\""), std::string::npos) << json;
        EXPECT_NE(json.find("\"points_total\": 6,"), std::string::npos) << json;
        EXPECT_NE(json.find("\"missing_points\": []"), std::string::npos) << json;
    }
    // Without the last shard the merge names its points; a shard's study.json that is not JSON is an error.
    shards.erase(shards.begin());
    EXPECT_EQ(study::merge_studies(shards, (dir / "part").string(), "merge"), (std::vector<std::int64_t>{4}));
    test::write_text(shards.front() + "/study.json", "{\"points_total\": 6,");
    try {
        study::merge_studies(shards, (dir / "bad").string(), "merge");
        ADD_FAILURE() << "accepted a broken study.json";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("study.json: invalid JSON at line 1"), std::string::npos) << e.what();
    }
}

TEST(StudyRun, StopFlagKeepsAValidPrefix)
{
    const auto dir = test::temp_dir();
    StudyOptions o;
    o.meshes = {two_boxes(dir, 2)};
    o.cell_size = {"x0.5:x2:6"};
    o.repeat = 1;
    o.oracle = false;
    o.out_dir = (dir / "out").string();
    auto plan = study::plan_study(o);
    std::atomic<bool> stop{false};
    study::RunHooks hooks;
    hooks.stop = &stop;
    hooks.on_point = [&](std::int64_t k, std::int64_t, const study::PointInfo&) {
        if (k == 2) stop = true;
    };
    const auto res = study::run_study(*plan, hooks);
    EXPECT_TRUE(res.interrupted);
    EXPECT_LT(res.points_done, 6);
    const Table t = Table::read_csv(res.csv_path);
    EXPECT_EQ(static_cast<std::int64_t>(t.rows.size()), res.rows);
    EXPECT_NE(test::read_text(res.json_path).find("\"interrupted\": true"), std::string::npos);
}

TEST(StudyScenarios, FiveTeschnerScenesHaveThePapersSizesAndRealContacts)
{
    const auto& specs = study::teschner_specs();
    ASSERT_EQ(specs.size(), 5u);
    EXPECT_EQ(specs[4].objects, 100);
    EXPECT_EQ(specs[4].tets, 50000);
    for (int i = 0; i < 5; ++i) {
        const auto sc = study::teschner_scenario(i);
        EXPECT_EQ(sc.mesh.num_objects(), sc.spec.objects) << sc.spec.name;
        EXPECT_NEAR(std::log(double(sc.mesh.num_tets()) / sc.spec.tets), 0.0, std::log(1.5))
            << sc.spec.name << " tets " << sc.mesh.num_tets();
        EXPECT_NEAR(std::log(double(sc.mesh.num_vertices()) / sc.spec.vertices), 0.0, std::log(1.6))
            << sc.spec.name << " vertices " << sc.mesh.num_vertices();
        if (i <= 2) { // the oracle is quick on the small ones: objects overlap, contacts between objects
            const auto contacts =
                brute_force_contacts(sc.mesh.positions, sc.mesh.tets, sc.mesh.vertex_object, sc.mesh.tet_object);
            std::set<Index> objects_touched;
            for (const auto& c : contacts)
                if (c.vertex_object != c.tet_object) {
                    objects_touched.insert(c.vertex_object);
                    objects_touched.insert(c.tet_object);
                }
            EXPECT_GT(contacts.size(), 0u) << sc.spec.name;
            EXPECT_EQ(static_cast<int>(objects_touched.size()), sc.spec.objects)
                << sc.spec.name; // every object overlaps another
        }
    }
    // Deterministic.
    EXPECT_EQ(study::teschner_scenario(1).mesh.positions, study::teschner_scenario(1).mesh.positions);
}

} // namespace
} // namespace tethash
