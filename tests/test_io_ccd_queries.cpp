// The CCD benchmark's query files (tethash/io/ccd_queries.hpp): rationals rounded to the nearest double, errors
// naming file and line, and the continuous queries (tethash/ccd.hpp) on the shared files of ../shared/ccd: no false
// negative, false positives no more than measured.
#include "support.hpp"
#include "tethash/ccd.hpp"
#include "tethash/io/ccd_queries.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <iterator>
#include <limits>
#include <random>

using namespace tethash;
namespace fs = std::filesystem;

TEST(IoCcdQueries, RationalsRoundToTheNearestDouble)
{
    EXPECT_EQ(io::rational_to_double("1", "3"), 1.0 / 3.0);
    EXPECT_EQ(io::rational_to_double("-2", "3"), -2.0 / 3.0);
    EXPECT_EQ(io::rational_to_double("0", "7"), 0.0);
    EXPECT_EQ(io::rational_to_double("+5", "1"), 5.0);
    // 2^53 + 1 is a tie between 2^53 and 2^53 + 2: to even, 2^53; 2^53 + 3 rounds up to 2^53 + 4.
    EXPECT_EQ(io::rational_to_double("9007199254740993", "1"), 9007199254740992.0);
    EXPECT_EQ(io::rational_to_double("9007199254740995", "1"), 9007199254740996.0);
    // Just above the tie (numerator and denominator beyond 64 bits): (2^53 + 1 + 2^-20) / 1, scaled by 2^20.
    EXPECT_EQ(io::rational_to_double("9444732965739291475969", "1048576"), 9007199254740994.0);
    // 2^66 and the benchmark's power-of-two denominators: exact.
    EXPECT_EQ(io::rational_to_double("73786976294838206464", "1"), std::ldexp(1.0, 66));
    EXPECT_EQ(io::rational_to_double("4131034501044815", "4503599627370496"), 4131034501044815.0 / std::ldexp(1.0, 52));
    // 1e30 / 1e29 = 10 exactly; 10^400 / 10^399 = 10.
    EXPECT_EQ(io::rational_to_double("1000000000000000000000000000000", "100000000000000000000000000000"), 10.0);
    EXPECT_EQ(io::rational_to_double("1" + std::string(400, '0'), "1" + std::string(399, '0')), 10.0);
    // Subnormals: 3 / 2^1076 = 0.75 · 2^-1074 rounds to 2^-1074; 1 / 2^1075 (a tie) to 0.
    std::string p1076 = "1";
    for (int i = 0; i < 1076; ++i) { // 2^1076 in decimal, by doubling
        int carry = 0;
        for (auto it = p1076.rbegin(); it != p1076.rend(); ++it) {
            const int d = (*it - '0') * 2 + carry;
            *it = static_cast<char>('0' + d % 10);
            carry = d / 10;
        }
        if (carry) p1076.insert(p1076.begin(), static_cast<char>('0' + carry));
    }
    EXPECT_EQ(io::rational_to_double("3", p1076), std::ldexp(1.0, -1074));
    EXPECT_EQ(io::rational_to_double("2", p1076), 0.0);
    test::expect_error([] { io::rational_to_double("1", "0"); }, {"zero denominator"});
    test::expect_error([] { io::rational_to_double("1.5", "2"); }, {"integer", "1.5"});
    test::expect_error([] { io::rational_to_double("1" + std::string(400, '0'), "1"); }, {"range"});
}

namespace {

/// One vertex-face query: the vertex from (1/4, 1/4, 1) to (1/4, 1/4, -1) through the triangle (0,0,0), (1,0,0),
/// (0,1,0); truth 1.
const char* kOneQuery = "1,4,1,4,1,1,1\n"
                        "0,1,0,1,0,1,1\n"
                        "1,1,0,1,0,1,1\n"
                        "0,1,1,1,0,1,1\n"
                        "1,4,1,4,-1,1,1\n"
                        "0,1,0,1,0,1,1\n"
                        "1,1,0,1,0,1,1\n"
                        "0,1,1,1,0,1,1\n";

} // namespace

TEST(IoCcdQueries, ReadsQueriesAndNamesFileAndLineOfErrors)
{
    const auto q = io::parse_ccd_queries("q.csv", std::string(kOneQuery) + "\n" + kOneQuery);
    ASSERT_EQ(q.size(), 2u);
    EXPECT_EQ(q[1].line, 10);
    EXPECT_TRUE(q[0].collides);
    EXPECT_EQ(q[0].points[0], Eigen::Vector3d(0.25, 0.25, 1));
    EXPECT_EQ(q[0].points[4], Eigen::Vector3d(0.25, 0.25, -1));
    const std::string good = kOneQuery;
    test::expect_error([&] { io::parse_ccd_queries("q.csv", good + "1,2,3\n"); }, {"q.csv:9:", "7 columns", "3"});
    test::expect_error([&] { io::parse_ccd_queries("q.csv", good.substr(0, good.size() - 14)); },
                       {"q.csv:7:", "multiple of 8"});
    std::string bad = good;
    bad.replace(bad.find("1,4,-1"), 6, "1,0,-1");
    test::expect_error([&] { io::parse_ccd_queries("q.csv", bad); }, {"q.csv:5:", "zero denominator"});
    bad = good;
    bad.replace(0, 1, "x");
    test::expect_error([&] { io::parse_ccd_queries("q.csv", bad); }, {"q.csv:1:", "column 1-2", "'x'"});
    bad = good;
    bad.replace(bad.size() - 2, 1, "0");
    test::expect_error([&] { io::parse_ccd_queries("q.csv", bad); }, {"q.csv:8:", "truth differs", "line 1"});
    bad = good;
    bad.replace(12, 1, "2");
    test::expect_error([&] { io::parse_ccd_queries("q.csv", bad); }, {"q.csv:1:", "truth 0 or 1", "'2'"});
    test::expect_error([] { io::read_ccd_queries("/nonexistent/q.csv"); }, {"/nonexistent/q.csv"});
}

namespace {

struct SetCount {
    std::int64_t queries = 0, false_negatives = 0, false_positives = 0;
};

SetCount run_shared(const std::string& type)
{
    SetCount n;
    const fs::path dir = fs::path(TETHASH_SHARED_CCD) / "unit-tests" / type;
    std::vector<fs::path> files;
    for (const auto& e : fs::directory_iterator(dir))
        if (e.path().extension() == ".csv") files.push_back(e.path());
    std::sort(files.begin(), files.end());
    for (const auto& f : files)
        for (const auto& q : io::read_ccd_queries(f.string())) {
            const auto& x = q.points;
            const ccd::CcdResult r = type == "edge-edge"
                                         ? ccd::edge_edge_ccd(x[0], x[1], x[2], x[3], x[4], x[5], x[6], x[7])
                                         : ccd::vertex_face_ccd(x[0], x[1], x[2], x[3], x[4], x[5], x[6], x[7]);
            ++n.queries;
            if (q.collides && !r.hit) {
                ++n.false_negatives;
                ADD_FAILURE() << "false negative: " << f.string() << ":" << q.line;
            }
            n.false_positives += !q.collides && r.hit;
            if (q.collides && r.hit) {
                EXPECT_LE(r.toi, 1.0);
            }
        }
    return n;
}

} // namespace

// The shared queries (250 vertex-face, 74 edge-edge, handcrafted degenerate motions): no false negative; the
// false positives measured were 0 for both types (tolerance 1e-6).
TEST(IoCcdQueries, SharedBenchmarkQueriesHaveNoFalseNegative)
{
    if (!fs::exists(fs::path(TETHASH_SHARED_CCD) / "unit-tests")) GTEST_SKIP() << "no ../shared/ccd";
    const SetCount vf = run_shared("vertex-face");
    const SetCount ee = run_shared("edge-edge");
    EXPECT_EQ(vf.queries, 250);
    EXPECT_EQ(ee.queries, 74);
    EXPECT_EQ(vf.false_negatives, 0);
    EXPECT_EQ(ee.false_negatives, 0);
    EXPECT_LE(vf.false_positives, 2);
    EXPECT_LE(ee.false_positives, 2);
}

TEST(IoCcdQueries, DoublesWrittenAsExactRationalsReadBackBitForBit)
{
    EXPECT_EQ(io::double_to_rational(0.0), "0,1");
    EXPECT_EQ(io::double_to_rational(-0.0), "0,1");
    EXPECT_EQ(io::double_to_rational(0.5), "1,2");
    EXPECT_EQ(io::double_to_rational(-0.75), "-3,4");
    EXPECT_EQ(io::double_to_rational(3.0), "3,1");
    EXPECT_EQ(io::double_to_rational(0x1p70), "1180591620717411303424,1");
    const std::string tiny = io::double_to_rational(std::ldexp(1.0, -1074));
    EXPECT_EQ(tiny.substr(0, 2), "1,");
    EXPECT_EQ(tiny.size(), 2 + 324U) << "2^1074 has 324 decimal digits";
    EXPECT_THROW(io::double_to_rational(std::nan("")), Error);
    std::mt19937_64 rng(29);
    std::uniform_real_distribution<double> mantissa(-1, 1);
    std::uniform_int_distribution<int> exponent(-1074, 1023);
    for (int i = 0; i < 5000; ++i) {
        const double x = i < 10 ? std::nextafter(std::numeric_limits<double>::max(), 0.0) / (i + 1)
                                : std::ldexp(mantissa(rng), exponent(rng));
        const std::string text = io::double_to_rational(x);
        const auto comma = text.find(',');
        ASSERT_NE(comma, std::string::npos);
        const double back = io::rational_to_double(text.substr(0, comma), text.substr(comma + 1));
        ASSERT_EQ(std::memcmp(&back, &x, sizeof x) == 0 || (x == 0 && back == 0), true) << text << " for " << x;
    }
}

TEST(IoCcdQueries, WrittenQueriesReadBackAndBadPathsLeaveNothing)
{
    std::mt19937_64 rng(7);
    std::uniform_real_distribution<double> d(-3, 3);
    std::vector<io::CcdQuery> queries(20);
    for (std::size_t q = 0; q < queries.size(); ++q) {
        for (auto& p : queries[q].points)
            p = Eigen::Vector3d(d(rng), d(rng) * 1e-7, d(rng) * 1e9);
        queries[q].collides = q % 3 == 0;
    }
    const fs::path dir = test::temp_dir() / "ccd_write";
    fs::remove_all(dir);
    fs::create_directories(dir);
    const std::string path = (dir / "q.csv").string();
    io::write_ccd_queries(path, queries);
    const auto back = io::read_ccd_queries(path);
    ASSERT_EQ(back.size(), queries.size());
    for (std::size_t q = 0; q < queries.size(); ++q) {
        EXPECT_EQ(back[q].collides, queries[q].collides);
        EXPECT_EQ(back[q].line, static_cast<std::int64_t>(8 * q + 1));
        for (std::size_t r = 0; r < 8; ++r)
            EXPECT_EQ(back[q].points[r], queries[q].points[r]) << "query " << q << " row " << r;
    }
    // A missing folder and a folder as the file are bad paths; a coordinate that is not finite is refused before
    // any file exists; the file that was there stays.
    EXPECT_THROW(io::write_ccd_queries((dir / "missing" / "q.csv").string(), queries), Error);
    EXPECT_THROW(io::write_ccd_queries(dir.string(), queries), Error);
    auto bad = queries;
    bad[4].points[6].y() = std::numeric_limits<double>::infinity();
    EXPECT_THROW(io::write_ccd_queries(path, bad), Error);
    EXPECT_EQ(io::read_ccd_queries(path).size(), queries.size());
    EXPECT_EQ(std::distance(fs::directory_iterator(dir), fs::directory_iterator{}), 1) << "no temporary left";
    fs::remove_all(dir);
}
