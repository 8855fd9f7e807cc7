// What a study is (spec.hpp): the names of the sweeps and the shard option.
#include "tethash/study/spec.hpp"
#include "tethash/detect_grammar.hpp"

#include "value_list.hpp"

#include "core/enum_names.hpp"

#include "tethash/detect.hpp"
#include "tethash/error.hpp"

namespace tethash::study {

namespace {
constexpr tethash::detail::EnumName<Sweep> k_sweep_names[] = {
    {Sweep::cell_size, "cell-size"}, {Sweep::table_size, "table-size"},
    {Sweep::hash, "hash"},           {Sweep::threads, "threads"},
    {Sweep::grid, "grid"},           {Sweep::integrator, "integrator"},
    {Sweep::stability, "stability"}, {Sweep::method, "method"},
};
} // namespace

Sweep parse_sweep(const std::string& name)
{
    if (const auto s = tethash::detail::value_named(k_sweep_names, name)) return *s;
    throw Error("sweep: unknown sweep '" + name +
                "' (expected cell-size, table-size, hash, threads, grid, method, integrator or stability)");
}

const char* to_string(Sweep s)
{
    return tethash::detail::name_of(k_sweep_names, s);
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
