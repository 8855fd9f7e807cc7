#pragma once
// Shared by the libFuzzer harnesses: the input goes to a file (the readers take paths), a reader
// may throw tethash::Error (bad input, the expected outcome), and anything it returns must be a
// consistent mesh. Any other exception, sanitizer report or abort is a finding.
#include "tethash/error.hpp"
#include "tethash/mesh.hpp"

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <unistd.h>

namespace tethash::fuzz {

/// A folder of this process for input files: $TMPDIR (or /dev/shm, else /tmp)/tethash-fuzz-PID.
inline const std::filesystem::path& work_dir()
{
    static const std::filesystem::path dir = [] {
        const char* tmp = std::getenv("TMPDIR");
        std::filesystem::path base =
            tmp && *tmp ? tmp : (std::filesystem::is_directory("/dev/shm") ? "/dev/shm" : "/tmp");
        std::filesystem::path d = base / ("tethash-fuzz-" + std::to_string(::getpid()));
        std::filesystem::create_directories(d);
        return d;
    }();
    return dir;
}

/// Writes `size` bytes to work_dir()/NAME and returns the path.
inline std::string write_input(const std::string& name, const std::uint8_t* data, std::size_t size)
{
    const std::filesystem::path p = work_dir() / name;
    std::ofstream out(p, std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
    out.close();
    if (!out) {
        std::fprintf(stderr, "fuzz: cannot write %s\n", p.string().c_str());
        std::abort();
    }
    return p.string();
}

/// A mesh a reader returned must pass the cheap consistency check; a reader that returns an
/// inconsistent mesh instead of throwing is a finding.
inline void expect_consistent(const TetMesh& mesh)
{
    try {
        mesh.check_consistency("fuzzed mesh");
    } catch (const Error& e) {
        std::fprintf(stderr, "fuzz: the reader returned an inconsistent mesh: %s\n", e.what());
        std::abort();
    }
}

} // namespace tethash::fuzz
