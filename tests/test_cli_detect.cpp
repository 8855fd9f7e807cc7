// `tethash detect`: scene from several files, CSV and JSON outputs, agreement with the oracle, bad options.
#include "cli_support.hpp"
#include "core_scenes.hpp"
#include "support.hpp"
#include "tethash/oracle.hpp"

#include <gtest/gtest.h>

#include <cstdio>
#include <sstream>

using namespace tethash;
using namespace tethash::test;

namespace {

/// A contacts CSV without its '#' header comment.
std::string csv_body(const std::string& text)
{
    std::istringstream in(text);
    std::string out;
    for (std::string line; std::getline(in, line);)
        if (line.empty() || line[0] != '#') out += line + "\n";
    return out;
}

const char* const kContactsHeader =
    "vertex,tet,vertex_object,tet_object,vertex_file,vertex_in_file,tet_file,tet_in_file,b0,b1,b2,b3";

struct Files {
    std::filesystem::path a, b;
    Scene scene; ///< a then b, as one scene
};

Files two_objects(const std::filesystem::path& dir)
{
    Files f;
    const Scene a = lattice_object(3, 3, 3, 0.25, Eigen::Vector3d(0, 0, 0));
    const Scene b = lattice_object(3, 3, 3, 0.25, Eigen::Vector3d(0.125, 0.125, 0.3));
    f.a = dir / "a.mesh";
    f.b = dir / "b.mesh";
    write_text(f.a, medit_text(a));
    write_text(f.b, medit_text(b));
    f.scene = a;
    append_object(f.scene, b);
    return f;
}

} // namespace

TEST(CliDetect, ContactsCsvMatchesOracleSortedWithHeader)
{
    const auto dir = temp_dir();
    const Files f = two_objects(dir);
    const auto r = run_tethash("detect " + quote(f.a) + " " + quote(f.b) + " --contacts " + quote(dir / "c.csv") +
                               " --stats " + quote(dir / "s.json") + " --threads 2 --repeat 3 --cell-size x1.5");
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_NE(r.out.find("contacts:"), std::string::npos);
    const std::vector<Contact> want =
        brute_force_contacts(f.scene.positions, f.scene.tets, f.scene.vertex_object, f.scene.tet_object);
    ASSERT_FALSE(want.empty());
    std::istringstream csv(csv_body(read_text(dir / "c.csv")));
    std::string line;
    ASSERT_TRUE(std::getline(csv, line));
    EXPECT_EQ(line, kContactsHeader);
    std::size_t i = 0;
    long prev_v = -1, prev_t = -1;
    while (std::getline(csv, line)) {
        long v = -1, t = -1;
        double b[4];
        ASSERT_EQ(std::sscanf(line.c_str(), "%ld,%ld,%*d,%*d,%*d,%*d,%*d,%*d,%lf,%lf,%lf,%lf", &v, &t, &b[0], &b[1],
                              &b[2], &b[3]),
                  6)
            << line;
        EXPECT_TRUE(v > prev_v || (v == prev_v && t > prev_t)) << "not sorted at row " << i;
        prev_v = v;
        prev_t = t;
        ASSERT_LT(i, want.size());
        EXPECT_EQ(v, want[i].vertex);
        EXPECT_EQ(t, want[i].tet);
        for (int k = 0; k < 4; ++k)
            EXPECT_NEAR(b[k], want[i].bary[k], 1e-9);
        ++i;
    }
    EXPECT_EQ(i, want.size());
    const std::string js = read_text(dir / "s.json");
    for (const char* key : {"\"vertices\": 128", "\"tets\": 324", "\"threads\": 2", "\"cell_size\"", "\"table_size\"",
                            "\"median_ms\"", "\"repeat\": 3"})
        EXPECT_NE(js.find(key), std::string::npos) << key << " in\n" << js;
    EXPECT_NE(js.find("\"contacts\": " + std::to_string(want.size())), std::string::npos) << js;
}

TEST(CliDetect, FirstCallIsReportedApartAndStagesAddUpToTheTotal)
{
    // The first call carries the one-off set-up (the automatic cell size); the timed calls follow it, and their
    // stages plus "other" are the printed total.
    const auto dir = temp_dir();
    const Files f = two_objects(dir);
    const auto r = run_tethash("detect " + quote(f.a) + " " + quote(f.b) + " --repeat 3 --threads 1 --stats " +
                               quote(dir / "s.json"));
    ASSERT_EQ(r.status, 0) << r.err;
    const auto at = r.out.find("first call: ");
    ASSERT_NE(at, std::string::npos) << r.out;
    EXPECT_NE(r.out.find("set-up", at), std::string::npos) << r.out;
    double total = 0, v = 0, t = 0, in = 0, so = 0, other = 0;
    int k = 0;
    const auto line = r.out.find("time: ");
    ASSERT_NE(line, std::string::npos) << r.out;
    ASSERT_EQ(std::sscanf(r.out.c_str() + line,
                          "time: %lf ms per detection (median of %d after the first): vertices %lf, tets %lf, inside "
                          "%lf, sort %lf, other %lf",
                          &total, &k, &v, &t, &in, &so, &other),
              7)
        << r.out;
    EXPECT_EQ(k, 3);
    EXPECT_NEAR(v + t + in + so + other, total, 0.003) << r.out;
    EXPECT_LE(other, 0.5 * total + 0.01) << "the stages should be most of a call: " << r.out;
    const std::string js = read_text(dir / "s.json");
    for (const char* key : {"\"first_call_ms\"", "\"setup_ms\"", "\"ms_setup\": 0"})
        EXPECT_NE(js.find(key), std::string::npos) << key << " in\n" << js;
}

TEST(CliDetect, NoSelfAndStaticObjects)
{
    const auto dir = temp_dir();
    const Files f = two_objects(dir);
    std::vector<ObjectOptions> objs(2);
    objs[0].self_collision = objs[1].self_collision = false;
    const auto want =
        brute_force_contacts(f.scene.positions, f.scene.tets, f.scene.vertex_object, f.scene.tet_object, objs);
    const auto r = run_tethash("detect " + quote(f.a) + " " + quote(f.b) +
                               " --no-self --static 0 --hash teschner "
                               "--table-size 17 --stats " +
                               quote(dir / "s.json"));
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_NE(read_text(dir / "s.json").find("\"contacts\": " + std::to_string(want.size())), std::string::npos);
    EXPECT_NE(read_text(dir / "s.json").find("\"table_size\": 17"), std::string::npos);
    const auto bad = run_tethash("detect " + quote(f.a) + " --static 3");
    expect_refused(bad, {"--static"});
}

TEST(CliDetect, BadOptionsExitTwoNamingTheOption)
{
    const auto dir = temp_dir();
    const Files f = two_objects(dir);
    struct Case {
        std::string args, fragment;
    };
    const Case cases[] = {{"--cell-size 0", "--cell-size"},
                          {"--cell-size -1", "--cell-size"},
                          {"--cell-size x0", "--cell-size"},
                          {"--cell-size abc", "--cell-size"},
                          {"--cell-size 1e999", "--cell-size"},
                          {"--table-size 0", "--table-size"},
                          {"--table-size -4", "--table-size"},
                          {"--table-size 3.5", "--table-size"},
                          {"--hash sha1", "sha1"},
                          {"--threads -1", "--threads"},
                          {"--repeat 0", "--repeat"},
                          {"--skin -0.1", "--skin"},
                          {"--skin xabc", "--skin"},
                          {"--skin nan", "--skin"}};
    for (const Case& c : cases) {
        const auto r = run_tethash("detect " + quote(f.a) + " " + c.args);
        EXPECT_EQ(r.status, 2) << c.args;
        EXPECT_NE(r.err.find(c.fragment), std::string::npos) << c.args << ": " << r.err;
    }
    const auto missing = run_tethash("detect " + quote(dir / "nope.mesh"));
    expect_refused(missing, {"nope.mesh"});
}

// Labels as objects: a Gmsh file with two bodies (physical tags 5 and 6); vertex 4 of body 6 lies in the
// tet of body 5 (tet 1). As one object that is a self-contact (gone with --no-self); as two objects it stays.
TEST(CliDetect, ObjectsFromLabels)
{
    const auto dir = temp_dir();
    write_text(dir / "bodies.msh", kTwoBodiesMsh);
    const std::string file = quote(dir / "bodies.msh");
    auto run = [&](const std::string& options) {
        const auto r = run_tethash("detect " + file + " " + options + " --contacts " + quote(dir / "c.csv"));
        EXPECT_EQ(r.status, 0) << options << "\n" << r.err;
        return std::make_pair(r.out, csv_body(read_text(dir / "c.csv")));
    };
    const std::string header = std::string(kContactsHeader) + "\n";
    auto [out, csv] = run("");
    EXPECT_NE(out.find("scene: 1 objects"), std::string::npos) << out;
    EXPECT_EQ(csv.rfind(header + "4,1,", 0), 0u) << csv;
    std::tie(out, csv) = run("--no-self");
    EXPECT_EQ(csv, header);
    std::tie(out, csv) = run("--no-self --objects-from-labels");
    EXPECT_NE(out.find("scene: 2 objects"), std::string::npos) << out;
    EXPECT_EQ(csv.rfind(header + "4,1,", 0), 0u) << csv;
    // Object 1 (label 6) static: its vertex in moving object 0 is still a contact; --static 2 is past the end.
    std::tie(out, csv) = run("--objects-from-labels --static 1");
    EXPECT_EQ(csv.rfind(header + "4,1,", 0), 0u) << csv;
    const auto bad = run_tethash("detect " + file + " --objects-from-labels --static 2");
    expect_refused(bad, {"--static"});
}

// With a skin the repeated detections reuse the first call's candidates: the same contacts as the oracle, and
// the statistics say that the last call reused them.
TEST(CliDetect, SkinReusesCandidatesWithTheSameContacts)
{
    const auto dir = temp_dir();
    const Files f = two_objects(dir);
    const auto want = brute_force_contacts(f.scene.positions, f.scene.tets, f.scene.vertex_object, f.scene.tet_object);
    const auto r = run_tethash("detect " + quote(f.a) + " " + quote(f.b) + " --skin x0.3 --repeat 3 --contacts " +
                               quote(dir / "c.csv") + " --stats " + quote(dir / "s.json"));
    ASSERT_EQ(r.status, 0) << r.err;
    const std::string js = read_text(dir / "s.json");
    EXPECT_NE(js.find("\"contacts\": " + std::to_string(want.size())), std::string::npos) << js;
    EXPECT_NE(js.find("\"reused\": 1"), std::string::npos) << js;
    std::istringstream csv(csv_body(read_text(dir / "c.csv")));
    std::string line;
    std::size_t rows = 0;
    while (std::getline(csv, line))
        ++rows;
    EXPECT_EQ(rows, want.size() + 1);
}
