// What a study is (spec.hpp): the names of the sweeps and the shard option.
#include "tethash/study/spec.hpp"

#include "value_list.hpp"

#include "tethash/detect.hpp"
#include "tethash/error.hpp"

namespace tethash::study {

Sweep parse_sweep(const std::string& name)
{
    if (name == "cell-size") return Sweep::cell_size;
    if (name == "table-size") return Sweep::table_size;
    if (name == "hash") return Sweep::hash;
    if (name == "threads") return Sweep::threads;
    if (name == "grid") return Sweep::grid;
    if (name == "integrator") return Sweep::integrator;
    if (name == "stability") return Sweep::stability;
    if (name == "method") return Sweep::method;
    throw Error("sweep: unknown sweep '" + name +
                "' (expected cell-size, table-size, hash, threads, grid, method, integrator or stability)");
}

const char* to_string(Sweep s)
{
    switch (s) {
    case Sweep::cell_size:
        return "cell-size";
    case Sweep::table_size:
        return "table-size";
    case Sweep::hash:
        return "hash";
    case Sweep::threads:
        return "threads";
    case Sweep::grid:
        return "grid";
    case Sweep::integrator:
        return "integrator";
    case Sweep::stability:
        return "stability";
    case Sweep::method:
        return "method";
    }
    return "?";
}

void parse_shard(const std::string& spec, int& index, int& count)
{
    const auto parts = split(spec, '/');
    if (parts.size() != 2) throw Error("--shard: expected I/N (0 <= I < N), found '" + spec + "'");
    long long i = 0, n = 0;
    try {
        i = parse_integer(trim(parts[0]), "--shard");
        n = parse_integer(trim(parts[1]), "--shard");
    } catch (const Error&) {
        throw Error("--shard: expected I/N (0 <= I < N), found '" + spec + "'");
    }
    if (n < 1 || i < 0 || i >= n || n > 1000000)
        throw Error("--shard: expected I/N (0 <= I < N), found '" + spec + "'");
    index = static_cast<int>(i);
    count = static_cast<int>(n);
}

} // namespace tethash::study
