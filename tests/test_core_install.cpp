// `cmake --install` of this build into a temporary prefix, then a separate consumer project configured with
// find_package(tethash) and linked to tethash::core is built and run.
#include "support.hpp"

#include <gtest/gtest.h>

#include <fstream>

using namespace tethash::test;

namespace {

/// `cmake --install` of this build into `prefix`.
void install_into(const std::filesystem::path& prefix)
{
    const std::filesystem::path build = std::filesystem::path(TETHASH_TEST_TMP).parent_path().parent_path();
    ASSERT_TRUE(std::filesystem::exists(build / "CMakeCache.txt")) << build;
    const auto inst = run_shell("cmake --install " + quote(build) + " --prefix " + quote(prefix));
    ASSERT_EQ(inst.status, 0) << inst.out << inst.err;
}

/// Configures and builds the consumer project tests/`project` against the installation in `prefix` (in `cbuild`)
/// and runs its `program`, which must succeed and report the contact of the small scene.
void build_and_run_consumer(const std::string& project, const std::string& program, const std::filesystem::path& prefix,
                            const std::filesystem::path& cbuild)
{
    const auto src = std::filesystem::path(TETHASH_SOURCE_DIR) / "tests" / project;
    const auto conf = run_shell("cmake -S " + quote(src) + " -B " + quote(cbuild) + " -DCMAKE_BUILD_TYPE=Release" +
                                " -DCMAKE_PREFIX_PATH=" + quote(prefix));
    ASSERT_EQ(conf.status, 0) << conf.out << conf.err;
    const auto bld = run_shell("cmake --build " + quote(cbuild) + " -j2");
    ASSERT_EQ(bld.status, 0) << bld.out << bld.err;
    const auto run = run_shell(quote(cbuild / program));
    EXPECT_EQ(run.status, 0) << run.out << run.err;
    EXPECT_NE(run.out.find("contact vertex 7 tet 0"), std::string::npos) << run.out;
}

} // namespace

TEST(CoreInstall, FindPackageConsumerBuildsAndRuns)
{
    const auto dir = temp_dir();
    const auto prefix = dir / "prefix";
    ASSERT_NO_FATAL_FAILURE(install_into(prefix));
    EXPECT_TRUE(std::filesystem::exists(prefix / "include/tethash/detect.hpp"));
    EXPECT_TRUE(std::filesystem::exists(prefix / "include/tethash/tethash.h"));   // the C interface
    EXPECT_TRUE(std::filesystem::exists(prefix / "include/tethash/tethash.f90")); // its Fortran module
    EXPECT_FALSE(std::filesystem::exists(prefix / "include/tethash/io"));         // core only
    build_and_run_consumer("install_consumer", "consumer", prefix, dir / "consumer");
}

TEST(CoreInstall, CConsumerBuildsAndRuns)
{
    if (run_shell("command -v cc").status != 0) GTEST_SKIP() << "no C compiler (cc)";
    const auto dir = temp_dir();
    const auto prefix = dir / "prefix";
    ASSERT_NO_FATAL_FAILURE(install_into(prefix));
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
