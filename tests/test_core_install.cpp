// The installed package as a consumer sees it: this build installed into one prefix (the ctest fixture
// install.prefix, tests/install_prefix.cmake), then separate consumer projects configured with find_package(tethash)
// against that prefix only, built and run: the documented consumer of docs/embedding.md verbatim, a C++ consumer
// with the oracle, a C program.
#include "support.hpp"

#include <gtest/gtest.h>

#include <fstream>
#include <sstream>

using namespace tethash::test;

namespace {

/// The prefix this build is installed in (the fixture install.prefix; installed here when the test runs alone).
std::filesystem::path installed_prefix()
{
    std::filesystem::path prefix = TETHASH_TEST_PREFIX;
    if (std::filesystem::exists(prefix / "include/tethash/detect.hpp")) return prefix;
    const std::filesystem::path build = std::filesystem::path(TETHASH_TEST_TMP).parent_path().parent_path();
    const auto inst = run_shell("cmake --install " + quote(build) + " --prefix " + quote(prefix));
    EXPECT_EQ(inst.status, 0) << inst.out << inst.err;
    return prefix;
}

/// Configures and builds the project in `src` against the installation in `prefix` only (in `cbuild`), with this
/// build's compiler and no C++ standard set.
void build_consumer(const std::filesystem::path& src, const std::filesystem::path& prefix,
                    const std::filesystem::path& cbuild)
{
    std::string launcher = TETHASH_TEST_CXX_LAUNCHER;
    if (!launcher.empty()) launcher = " -DCMAKE_CXX_COMPILER_LAUNCHER=" + quote(launcher);
    const auto conf = run_shell("cmake -S " + quote(src) + " -B " + quote(cbuild) + " -DCMAKE_BUILD_TYPE=Release" +
                                " -DCMAKE_CXX_COMPILER=" + quote(TETHASH_TEST_CXX) + launcher +
                                " -DCMAKE_PREFIX_PATH=" + quote(prefix));
    ASSERT_EQ(conf.status, 0) << conf.out << conf.err;
    const auto bld = run_shell("cmake --build " + quote(cbuild) + " -j2");
    ASSERT_EQ(bld.status, 0) << bld.out << bld.err;
}

/// Builds the consumer project tests/`project` against `prefix` (in `cbuild`) and runs its `program`, which must
/// succeed and report the contact of the small scene.
void build_and_run_consumer(const std::string& project, const std::string& program, const std::filesystem::path& prefix,
                            const std::filesystem::path& cbuild)
{
    ASSERT_NO_FATAL_FAILURE(
        build_consumer(std::filesystem::path(TETHASH_SOURCE_DIR) / "tests" / project, prefix, cbuild));
    const auto run = run_shell(quote(cbuild / program));
    EXPECT_EQ(run.status, 0) << run.out << run.err;
    EXPECT_NE(run.out.find("contact vertex 7 tet 0"), std::string::npos) << run.out;
}

/// The fenced code block that follows the line containing `marker` in `markdown` (empty when there is none).
std::string fenced_block_after(const std::string& markdown, const std::string& marker)
{
    const auto at = markdown.find(marker);
    if (at == std::string::npos) return {};
    std::istringstream in(markdown.substr(at));
    std::string line, block;
    bool inside = false;
    std::getline(in, line); // the marker's line
    while (std::getline(in, line)) {
        if (line.rfind("```", 0) == 0) {
            if (inside) return block;
            inside = true;
            continue;
        }
        if (inside) block += line + "\n";
    }
    return {};
}

} // namespace

TEST(CoreInstall, FindPackageConsumerBuildsAndRuns)
{
    const auto dir = temp_dir();
    const auto prefix = installed_prefix();
    EXPECT_TRUE(std::filesystem::exists(prefix / "include/tethash/detect.hpp"));
    EXPECT_TRUE(std::filesystem::exists(prefix / "include/tethash/tethash.h"));   // the C interface
    EXPECT_TRUE(std::filesystem::exists(prefix / "include/tethash/tethash.f90")); // its Fortran module
    // An embedder's surface: not the options' text grammar nor the broad phases' splitting-plane tree.
    EXPECT_FALSE(std::filesystem::exists(prefix / "include/tethash/detect_grammar.hpp"));
    EXPECT_FALSE(std::filesystem::exists(prefix / "include/tethash/split_tree.hpp"));
    // The io and meshing components with their headers; not the simulator's or the studies'.
    EXPECT_TRUE(std::filesystem::exists(prefix / "include/tethash/io/mesh_io.hpp"));
    EXPECT_TRUE(std::filesystem::exists(prefix / "include/tethash/meshing/generate.hpp"));
    EXPECT_FALSE(std::filesystem::exists(prefix / "include/tethash/sim"));
    EXPECT_FALSE(std::filesystem::exists(prefix / "include/tethash/study"));
    build_and_run_consumer("install_consumer", "consumer", prefix, dir / "consumer");

    // A component the package does not have is named.
    const auto other = dir / "other_component";
    std::filesystem::create_directories(other);
    write_text(other / "CMakeLists.txt", "cmake_minimum_required(VERSION 3.25)\nproject(other LANGUAGES CXX)\n"
                                         "find_package(tethash REQUIRED COMPONENTS io sim)\n");
    const auto bad = run_shell("cmake -S " + quote(other) + " -B " + quote(other / "build") +
                               " -DCMAKE_PREFIX_PATH=" + quote(prefix));
    EXPECT_NE(bad.status, 0);
    EXPECT_NE((bad.out + bad.err).find("tethash has no component 'sim' (components: io, meshing)"), std::string::npos)
        << bad.out << bad.err;
}

TEST(CoreInstall, CConsumerBuildsAndRuns)
{
    if (run_shell("command -v cc").status != 0) GTEST_SKIP() << "no C compiler (cc)";
    const auto dir = temp_dir();
    const auto prefix = installed_prefix();
    ASSERT_NO_FATAL_FAILURE(build_and_run_consumer("install_consumer_c", "detect_c", prefix, dir / "consumer"));

    // A project without CXX is told why find_package(tethash) fails.
    const auto c_only = dir / "c_only";
    std::filesystem::create_directories(c_only);
    {
        std::ofstream cm(c_only / "CMakeLists.txt");
        cm << "cmake_minimum_required(VERSION 3.25)\nproject(c_only LANGUAGES C)\nfind_package(tethash REQUIRED)\n";
    }
    const auto bad = run_shell("cmake -S " + quote(c_only) + " -B " + quote(c_only / "build") +
                               " -DCMAKE_PREFIX_PATH=" + quote(prefix));
    EXPECT_NE(bad.status, 0);
    EXPECT_NE((bad.out + bad.err).find("enable CXX"), std::string::npos) << bad.out << bad.err;
}

// docs/embedding.md's CMakeLists.txt and solver.cpp, copied verbatim: they configure with no C++ standard set (the
// installed tethash::core asks for C++20), build against the installed package only (catching tethash::Error after
// the documented includes), and run.
TEST(CoreInstall, DocumentedConsumerBuildsVerbatim)
{
    const auto doc = read_text(std::filesystem::path(TETHASH_SOURCE_DIR) / "docs/embedding.md");
    const std::string cmake = fenced_block_after(doc, "CMakeLists.txt of the documented consumer");
    const std::string cpp = fenced_block_after(doc, "solver.cpp of the documented consumer");
    ASSERT_NE(cmake.find("find_package(tethash REQUIRED)"), std::string::npos) << cmake;
    ASSERT_NE(cpp.find("int main"), std::string::npos) << cpp;
    // The documented includes (detect.hpp, penetration.hpp) bring what the catch needs.
    ASSERT_NE(cpp.find("catch (const tethash::Error& e)"), std::string::npos) << cpp;
    ASSERT_EQ(cpp.find("tethash/error.hpp"), std::string::npos) << cpp;
    EXPECT_EQ(cmake.find("CMAKE_CXX_STANDARD"), std::string::npos) << "the documented consumer sets no standard";
    const auto dir = temp_dir();
    std::filesystem::create_directories(dir / "src");
    write_text(dir / "src/CMakeLists.txt", cmake);
    write_text(dir / "src/solver.cpp", cpp);
    ASSERT_NO_FATAL_FAILURE(build_consumer(dir / "src", installed_prefix(), dir / "build"));
    const auto run = run_shell(quote(dir / "build/solver"));
    EXPECT_EQ(run.status, 0) << run.out << run.err;
    // Node 7 inside the unit tet 0 at every iteration, at a depth within the tet; no other contact.
    std::istringstream lines(run.out);
    std::string line;
    int found = 0;
    while (std::getline(lines, line)) {
        const std::string head = "node 7 inside tet 0, depth ";
        ASSERT_EQ(line.rfind(head, 0), 0U) << run.out;
        const double depth = std::stod(line.substr(head.size()));
        EXPECT_TRUE(depth > 0 && depth < 1) << line;
        ++found;
    }
    EXPECT_EQ(found, 3) << run.out;
}
