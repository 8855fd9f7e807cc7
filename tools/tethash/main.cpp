// The tethash command line. Exit status: 0 success, 1 failure while running, 2 bad input or usage.
#include "command.hpp"

#include "tethash/error.hpp"
#include "tethash/io/mesh_io.hpp"

#include <algorithm>
#include <csignal>
#include <cstdio>
#include <iostream>
#include <string>
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

bool stderr_is_terminal()
{
    return isatty(fileno(stderr)) != 0;
}

void add_objects_from_labels_option(CLI::App& sub, std::string& value)
{
    sub.add_flag("--objects-from-labels{separate}", value,
                 "[=separate|join] Each tet label of a file (Gmsh physical tag, else entity tag; Medit ref; "
                 "TetGen region attribute) is an object, numbered in label order; a vertex in tets of two labels "
                 "is an error, or with =join makes those labels one object. Without it each file is one object, "
                 "or the objects of its 'object' cell data (simulation frames); labels take precedence");
}

void add_linearize_option(CLI::App& sub, bool& value)
{
    sub.add_flag("--linearize", value,
                 "Read quadratic (10-node) tets of .vtu, .vtk and .msh files as 4-node tets of their corner nodes; "
                 "the mid-edge nodes are dropped");
}

void check_objects_from_labels_value(const std::string& value)
{
    if (!value.empty() && value != "separate" && value != "join")
        throw Error("--objects-from-labels: expected 'separate' or 'join', got '" + value + "'");
}

std::string objects_from_labels(TetMesh& mesh, const std::string& path, const std::string& value)
{
    const bool join = value == "join";
    if (mesh.tet_label.empty()) {
        split_objects_by_label(mesh);
        return "no tet labels: the file is one object";
    }
    LabelSplit split;
    try {
        split = split_objects_by_label(mesh, join ? SharedLabelVertices::join : SharedLabelVertices::error, path);
    } catch (const Error& e) {
        throw Error(std::string(e.what()) + " (--objects-from-labels=join makes such labels one object)");
    }
    std::string note = std::to_string(split.object_labels.size()) + " objects from tet labels";
    std::size_t joined = 0;
    for (const auto& labels : split.object_labels)
        joined += labels.size() > 1;
    if (joined)
        note += " (" + std::to_string(split.shared_vertices) + " shared vertices joined labels into " +
                std::to_string(joined) + " objects)";
    return note;
}

} // namespace tethash::cli

namespace {

/// SIGINT/SIGTERM/SIGHUP: remove the temporary files of writes in progress (the target keeps its old
/// content), then die of the signal as usual. Commands with their own handling (study) replace it.
extern "C" void on_fatal_signal(int sig)
{
    tethash::io::remove_temporaries_now();
    std::signal(sig, SIG_DFL);
    std::raise(sig);
}

} // namespace

int main(int argc, char** argv)
{
    for (int sig : {SIGINT, SIGTERM, SIGHUP})
        if (std::signal(sig, on_fatal_signal) == SIG_IGN) std::signal(sig, SIG_IGN); // ignored stays ignored (nohup, &)
    using namespace tethash;
    CLI::App app{"tethash: collision detection for deformable tetrahedral meshes by spatial hashing,\n"
                 "and a mass-spring simulator that uses it.",
                 "tethash"}; // named: usage lines say "tethash", not the path it was started by
    // Usage errors: one line, like every other error, naming the subcommand whose help explains it.
    app.failure_message([](const CLI::App* a, const CLI::Error& e) {
        std::string help = "tethash";
        for (const CLI::App* sub = a; sub && !sub->get_subcommands().empty();) {
            sub = sub->get_subcommands().front();
            help += " " + sub->get_name();
        }
        return std::string("tethash: error: ") + e.what() + " (see '" + help + " --help')\n";
    });
    app.set_version_flag("--version", std::string("tethash ") + TETHASH_VERSION);
    app.require_subcommand(1);
    auto& commands = cli::registry();
    std::sort(commands.begin(), commands.end(), [](const auto& a, const auto& b) { return a.name < b.name; });
    for (auto& c : commands) {
        CLI::App* sub = app.add_subcommand(c.name, c.description);
        c.setup(*sub);
        // The separator rule of every command: an option takes one value per occurrence (repeat it, or give a
        // comma list where the option says so), so options and positional arguments mix in any order:
        // `detect --static 0 a.vtu b.vtu` is --static 0 and two meshes.
        for (CLI::Option* opt : sub->get_options())
            if (!opt->get_positional() && opt->get_expected_min() <= 1 && opt->get_allow_extra_args())
                opt->allow_extra_args(false);
    }
    try {
        if (argc > 1 && argv[1][0] != '-' &&
            std::none_of(commands.begin(), commands.end(), [&](const auto& c) { return c.name == argv[1]; })) {
            std::string names;
            for (const auto& c : commands)
                names += (names.empty() ? "" : ", ") + c.name;
            throw Error(std::string("unknown command '") + argv[1] + "' (commands: " + names +
                        "; see 'tethash --help')");
        }
        app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
        // --help and --version exit 0; every usage error exits 2.
        const int code = app.exit(e);
        return code == 0 ? 0 : 2;
    } catch (const Error& e) {
        std::fprintf(stderr, "tethash: error: %s\n", e.what());
        return 2;
    } catch (const RunFailure& e) {
        // A run that failed, or a write the file system refused (WriteError: full disk, no permission).
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
