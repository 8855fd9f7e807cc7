#pragma once
// Helpers shared by the tests: running the tethash program, temporary folders, expected errors and refusals,
// finding a Python interpreter that imports given modules, the shared real meshes.
#include "tethash/error.hpp"
#include "tethash/mesh.hpp"

#include <gtest/gtest.h>

#include <array>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <initializer_list>
#include <optional>
#include <sstream>
#include <string>
#include <sys/wait.h>
#include <vector>

namespace tethash::test {

/// An n × C matrix (Positions, Tets, Triangles) from n rows of C values each (Eigen vectors or std::arrays).
template <class Matrix, class Row> Matrix matrix_of(const std::vector<Row>& rows)
{
    Matrix m(static_cast<Eigen::Index>(rows.size()), Matrix::ColsAtCompileTime);
    for (std::size_t i = 0; i < rows.size(); ++i)
        for (int c = 0; c < Matrix::ColsAtCompileTime; ++c)
            m(static_cast<Eigen::Index>(i), c) = rows[i].data()[c];
    return m;
}

/// The 6 tets of the Kuhn split of lattice cube (i, j, k), the monotone paths from its corner (i, j, k) to
/// (i + 1, j + 1, k + 1), in the vertex ids id(i', j', k') of the lattice points (orientation not fixed).
template <class Id> std::array<std::array<Index, 4>, 6> kuhn_tets(int i, int j, int k, Id&& id)
{
    // Corner b of the cube is at offset (b & 1, b >> 1 & 1, b >> 2 & 1).
    static constexpr int corners[6][4] = {{0, 1, 3, 7}, {0, 1, 5, 7}, {0, 2, 3, 7},
                                          {0, 2, 6, 7}, {0, 4, 5, 7}, {0, 4, 6, 7}};
    std::array<std::array<Index, 4>, 6> out{};
    for (std::size_t t = 0; t < 6; ++t)
        for (std::size_t a = 0; a < 4; ++a) {
            const int b = corners[t][a];
            out[t][a] = static_cast<Index>(id(i + (b & 1), j + ((b >> 1) & 1), k + ((b >> 2) & 1)));
        }
    return out;
}

struct RunResult {
    int status = -1; ///< exit status
    std::string out; ///< standard output
    std::string err; ///< standard error
};

/// A fresh empty folder under the build tree, named after the running test.
inline std::filesystem::path temp_dir()
{
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    std::string name = info ? std::string(info->test_suite_name()) + "." + info->name() : "misc";
    for (char& c : name)
        if (c == '/') c = '_';
    std::filesystem::path p = std::filesystem::path(TETHASH_TEST_TMP) / name;
    std::filesystem::remove_all(p);
    std::filesystem::create_directories(p);
    return p;
}

inline std::string read_text(const std::filesystem::path& p)
{
    std::ifstream in(p, std::ios::binary);
    std::stringstream ss;
    ss << in.rdbuf();
    return ss.str();
}

inline void write_text(const std::filesystem::path& p, const std::string& text)
{
    std::ofstream out(p, std::ios::binary);
    out << text;
}

/// Runs a shell command line; captures stdout and stderr through files.
inline RunResult run_shell(const std::string& cmdline)
{
    static int counter = 0;
    const auto dir = std::filesystem::path(TETHASH_TEST_TMP) / "_run";
    std::filesystem::create_directories(dir);
    const std::string tag = std::to_string(::getpid()) + "_" + std::to_string(counter++);
    const auto out = dir / ("out_" + tag), err = dir / ("err_" + tag);
    const std::string full = cmdline + " >'" + out.string() + "' 2>'" + err.string() + "' </dev/null";
    const int raw = std::system(full.c_str());
    RunResult r;
    r.status = WIFEXITED(raw) ? WEXITSTATUS(raw) : -1;
    r.out = read_text(out);
    r.err = read_text(err);
    std::filesystem::remove(out);
    std::filesystem::remove(err);
    return r;
}

/// Single-quoted for the shell (built by appending: g++ 12 warns falsely on "'" + string + "'").
inline std::string quote(const std::filesystem::path& p)
{
    std::string q;
    q.reserve(p.string().size() + 2);
    q.push_back('\'');
    q.append(p.string());
    q.push_back('\'');
    return q;
}

/// Runs the tethash program with the given arguments (already shell-quoted where needed).
inline RunResult run_tethash(const std::string& args)
{
    std::string cmd = quote(TETHASH_EXE);
    cmd.push_back(' ');
    cmd.append(args);
    return run_shell(cmd);
}

/// Runs `fn` and expects a tethash::Error whose message contains each of `parts`; returns the message.
inline std::string expect_error(const std::function<void()>& fn, const std::vector<std::string>& parts)
{
    try {
        fn();
    } catch (const Error& e) {
        const std::string msg = e.what();
        for (const std::string& part : parts)
            EXPECT_NE(msg.find(part), std::string::npos) << "'" << part << "' not in: " << msg;
        return msg;
    } catch (const std::exception& e) {
        ADD_FAILURE() << "expected tethash::Error, got another exception: " << e.what();
        return e.what();
    }
    ADD_FAILURE() << "expected tethash::Error, nothing was thrown";
    return {};
}

/// Expects `r` to be a refusal of bad input: exit status 2 and a message on stderr containing each of `parts`.
inline void expect_refused(const RunResult& r, std::initializer_list<std::string> parts)
{
    EXPECT_EQ(r.status, 2) << r.err;
    for (const std::string& part : parts)
        EXPECT_NE(r.err.find(part), std::string::npos) << "'" << part << "' not in: " << r.err;
}

/// A Python interpreter that imports every module in `modules` (space separated), or nullopt.
/// Tries /usr/bin/python3 (Debian's packages install there) before the python3 first on PATH.
inline std::optional<std::string> python_with(const std::string& modules)
{
    std::string imports;
    std::istringstream ss(modules);
    for (std::string m; ss >> m;)
        imports += "import " + m + ";";
    for (const char* candidate : {"/usr/bin/python3", "python3"}) {
        const std::string cmd = std::string(candidate) + " -c '" + imports + "' >/dev/null 2>&1";
        if (std::system(cmd.c_str()) == 0) return std::string(candidate);
    }
    return std::nullopt;
}

/// .ci/run repeats the kernels' tests with TETHASH_SIMD=scalar (the path of machines without AVX2): a kernel
/// family's chosen `kernel` must then be the scalar one, else one of the two.
inline void expect_kernel_follows_tethash_simd(const std::string& kernel)
{
    const char* env = std::getenv("TETHASH_SIMD");
    if (env && std::string(env) == "scalar")
        EXPECT_EQ(kernel, "scalar");
    else
        EXPECT_TRUE(kernel == "avx2" || kernel == "scalar") << kernel;
}

/// Path of a mesh in ../shared/meshes, or nullopt if the folder or the file is absent.
inline std::optional<std::filesystem::path> shared_mesh(const std::string& name)
{
    std::filesystem::path p = std::filesystem::path(TETHASH_SHARED_MESHES) / name;
    if (std::filesystem::exists(p)) return p;
    return std::nullopt;
}

} // namespace tethash::test

#define TETHASH_SKIP_WITHOUT_PYTHON(var, modules)                                                                      \
    auto var##_opt = ::tethash::test::python_with(modules);                                                            \
    if (!var##_opt) GTEST_SKIP() << "no python3 that imports: " << modules;                                            \
    const std::string var = *var##_opt
