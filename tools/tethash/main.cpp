// The tethash command line. Exit status: 0 success, 1 failure while running, 2 bad input or usage.
#include "command.hpp"

#include "tethash/error.hpp"

#include <algorithm>
#include <cstdio>
#include <iostream>
#include <unistd.h>

#ifdef _OPENMP
#include <omp.h>
#endif

namespace tethash::cli {

std::vector<Command>& registry()
{
    static std::vector<Command> commands;
    return commands;
}

int set_threads(int n)
{
#ifdef _OPENMP
    if (n > 0) omp_set_num_threads(n);
    return omp_get_max_threads();
#else
    (void)n;
    return 1;
#endif
}

bool stderr_is_terminal() { return isatty(fileno(stderr)) != 0; }

} // namespace tethash::cli

int main(int argc, char** argv)
{
    using namespace tethash;
    CLI::App app{"tethash: collision detection for deformable tetrahedral meshes by spatial hashing,\n"
                 "and a mass-spring simulator that uses it."};
    app.set_version_flag("--version", std::string("tethash ") + TETHASH_VERSION);
    app.require_subcommand(1);
    auto& commands = cli::registry();
    std::sort(commands.begin(), commands.end(), [](const auto& a, const auto& b) { return a.name < b.name; });
    for (auto& c : commands) {
        CLI::App* sub = app.add_subcommand(c.name, c.description);
        c.setup(*sub);
    }
    try {
        app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
        // --help and --version exit 0; every usage error exits 2.
        const int code = app.exit(e);
        return code == 0 ? 0 : 2;
    } catch (const Error& e) {
        std::fprintf(stderr, "tethash: error: %s\n", e.what());
        return 2;
    } catch (const RunFailure& e) {
        std::fprintf(stderr, "tethash: failed: %s\n", e.what());
        return 1;
    } catch (const std::bad_alloc&) {
        std::fprintf(stderr, "tethash: failed: out of memory\n");
        return 1;
    } catch (const std::exception& e) {
        std::fprintf(stderr, "tethash: failed: %s\n", e.what());
        return 1;
    }
    return 0;
}
