// `cmake --install` of this build into a temporary prefix, then a separate consumer project configured with
// find_package(tethash) and linked to tethash::core is built and run.
#include "support.hpp"

#include <gtest/gtest.h>

#include <fstream>

using namespace tethash::test;

TEST(CoreInstall, FindPackageConsumerBuildsAndRuns)
{
    const auto dir = temp_dir();
    const std::filesystem::path build = std::filesystem::path(TETHASH_TEST_TMP).parent_path().parent_path();
    ASSERT_TRUE(std::filesystem::exists(build / "CMakeCache.txt")) << build;
    const auto prefix = dir / "prefix";
    const auto inst = run_shell("cmake --install " + quote(build) + " --prefix " + quote(prefix));
    ASSERT_EQ(inst.status, 0) << inst.out << inst.err;
    EXPECT_TRUE(std::filesystem::exists(prefix / "include/tethash/detect.hpp"));
    EXPECT_TRUE(std::filesystem::exists(prefix / "include/tethash/tethash.h"));   // the C interface
    EXPECT_TRUE(std::filesystem::exists(prefix / "include/tethash/tethash.f90")); // its Fortran module
    EXPECT_FALSE(std::filesystem::exists(prefix / "include/tethash/io"));         // core only

    const auto src = std::filesystem::path(TETHASH_SOURCE_DIR) / "tests/install_consumer";
    const auto cbuild = dir / "consumer";
    const auto conf = run_shell("cmake -S " + quote(src) + " -B " + quote(cbuild) +
                                " -DCMAKE_BUILD_TYPE=Release"
                                " -DCMAKE_PREFIX_PATH=" +
                                quote(prefix));
    ASSERT_EQ(conf.status, 0) << conf.out << conf.err;
    const auto bld = run_shell("cmake --build " + quote(cbuild) + " -j2");
    ASSERT_EQ(bld.status, 0) << bld.out << bld.err;
    const auto run = run_shell(quote(cbuild / "consumer"));
    EXPECT_EQ(run.status, 0) << run.out << run.err;
    EXPECT_NE(run.out.find("contact vertex 7 tet 0"), std::string::npos) << run.out;
}

TEST(CoreInstall, CConsumerBuildsAndRuns)
{
    if (run_shell("command -v cc").status != 0) GTEST_SKIP() << "no C compiler (cc)";
    const auto dir = temp_dir();
    const std::filesystem::path build = std::filesystem::path(TETHASH_TEST_TMP).parent_path().parent_path();
    const auto prefix = dir / "prefix";
    const auto inst = run_shell("cmake --install " + quote(build) + " --prefix " + quote(prefix));
    ASSERT_EQ(inst.status, 0) << inst.out << inst.err;
    const auto src = std::filesystem::path(TETHASH_SOURCE_DIR) / "tests/install_consumer_c";
    const auto cbuild = dir / "consumer";
    const auto conf = run_shell("cmake -S " + quote(src) + " -B " + quote(cbuild) + " -DCMAKE_BUILD_TYPE=Release" +
                                " -DCMAKE_PREFIX_PATH=" + quote(prefix));
    ASSERT_EQ(conf.status, 0) << conf.out << conf.err;
    const auto bld = run_shell("cmake --build " + quote(cbuild) + " -j2");
    ASSERT_EQ(bld.status, 0) << bld.out << bld.err;
    const auto run = run_shell(quote(cbuild / "detect_c"));
    EXPECT_EQ(run.status, 0) << run.out << run.err;
    EXPECT_NE(run.out.find("contact vertex 7 tet 0"), std::string::npos) << run.out;

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
