// The study's outputs (report.hpp): the output folder, study.json and the merge of shards.
#include "report.hpp"

#include "json_read.hpp"
#include "value_list.hpp"

#include "tethash/error.hpp"
#include "tethash/io/mesh_io.hpp"

#include <algorithm>
#include <cstdlib>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <thread>

#ifdef _OPENMP
#include <omp.h>
#endif

namespace tethash::study {

namespace fs = std::filesystem;

namespace {

std::string read_file_text(const std::string& path)
{
    std::ifstream in(path, std::ios::binary);
    std::stringstream ss;
    ss << in.rdbuf();
    return ss.str();
}

std::string utc_now()
{
    const std::time_t t = std::time(nullptr);
    std::tm tm{};
    gmtime_r(&t, &tm);
    char buf[32];
    std::strftime(buf, sizeof buf, "%Y-%m-%dT%H:%M:%SZ", &tm);
    return buf;
}

} // namespace

void check_out_dir(const std::string& dir)
{
    fs::path p(dir);
    while (!p.empty() && !fs::exists(p) && p.has_parent_path() && p.parent_path() != p)
        p = p.parent_path();
    if (p.empty() || !fs::exists(p)) p = ".";
    if (!fs::is_directory(p)) throw Error("--out: " + dir + ": '" + p.string() + "' exists and is not a folder");
    io::check_output_file((p / "study.csv").string(), "--out " + dir);
}

void make_out_dir(const std::string& dir)
{
    std::error_code ec;
    fs::create_directories(dir, ec);
    if (ec) {
        // A file on the way is a bad --out; anything else is the file system refusing.
        const std::string msg = "--out: cannot create folder '" + dir + "': " + ec.message();
        if (ec == std::errc::not_a_directory || ec == std::errc::file_exists) throw Error(msg);
        throw WriteError(msg);
    }
}

void write_machine(JsonWriter& j, const std::string& compiler_flags)
{
    std::string cpu = "unknown";
    {
        std::ifstream in("/proc/cpuinfo");
        for (std::string line; std::getline(in, line);)
            if (line.rfind("model name", 0) == 0) {
                const auto colon = line.find(':');
                if (colon != std::string::npos) cpu = trim(line.substr(colon + 1));
                break;
            }
    }
    std::string host = "unknown";
    std::ifstream("/proc/sys/kernel/hostname") >> host;
#ifdef _OPENMP
    const int omp_threads = omp_get_max_threads();
#else
    const int omp_threads = 1;
#endif
#if defined(__clang__)
    const std::string compiler = std::string("clang ") + __clang_version__;
#elif defined(__GNUC__)
    const std::string compiler = std::string("g++ ") + __VERSION__;
#else
    const std::string compiler = "unknown";
#endif
    j.begin_object(JsonWriter::inline_layout)
        .member("cores", std::thread::hardware_concurrency())
        .member("cpu", cpu)
        .member("host", host)
        .member("openmp_max_threads", omp_threads)
        .member("compiler", compiler)
        .member("flags", compiler_flags)
        .member("date", utc_now())
        .end_object();
}

void write_run_members(JsonWriter& j, const std::string& command_line, const std::string& compiler_flags)
{
    j.member("command", command_line).key("machine");
    write_machine(j, compiler_flags);
}

void write_json_file(const std::string& path, const JsonWriter& j)
{
    io::write_text_file(path, j.str() + "\n");
}

void write_summary(JsonWriter& j, const Table& t)
{
    const int ip = t.index_of("point");
    if (ip < 0) throw Error("study table: no 'point' column");
    std::map<long long, std::vector<const Row*>> groups;
    for (const Row& r : t.rows)
        groups[std::atoll(r[static_cast<std::size_t>(ip)].c_str())].push_back(&r);
    j.begin_array(JsonWriter::block_layout);
    for (const auto& [point, rows] : groups) {
        j.begin_object(JsonWriter::inline_layout).member("point", point).member("repeats", rows.size());
        for (std::size_t c = 0; c < t.columns.size(); ++c) {
            const std::string& name = t.columns[c];
            if (name == "point" || name == "repeat") continue;
            j.key(name);
            if (!is_timing_column(name)) {
                j.number_text((*rows.front())[c]);
                continue;
            }
            std::vector<double> v;
            for (const Row* r : rows)
                if (!(*r)[c].empty()) v.push_back(std::strtod((*r)[c].c_str(), nullptr));
            if (v.empty()) {
                j.null();
                continue;
            }
            std::sort(v.begin(), v.end());
            const std::size_t n = v.size();
            const double median = n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
            j.begin_object()
                .key("median")
                .number_text(fmt_double(median))
                .key("min")
                .number_text(fmt_double(v.front()))
                .key("max")
                .number_text(fmt_double(v.back()))
                .end_object();
        }
        j.end_object();
    }
    j.end_array();
}

void write_study_json(const StudyPlan& plan, const StudyResult& res, const Table& table, double seconds)
{
    const StudyOptions& o = plan.options;
    JsonWriter j;
    j.begin_object().member("tethash_study", 1).member("sweep", to_string(o.sweep));
    write_run_members(j, o.command_line, o.compiler_flags);
    j.member("points_total", points_total(plan))
        .key("shard")
        .begin_object(JsonWriter::inline_layout)
        .member("index", o.shard_index)
        .member("count", o.shard_count)
        .end_object()
        .member("points_planned", res.points_planned)
        .member("points_done", res.points_done)
        .member("rows", res.rows)
        .member("repeat", o.repeat)
        .member("warmup", o.warmup)
        .member("interrupted", res.interrupted)
        .key("seconds")
        .number_text(fmt_double(seconds));
    j.key("scenes").begin_array();
    for (const auto& sc : plan.scenes)
        j.begin_object()
            .member("name", sc.name)
            .member("source", sc.source)
            .member("objects", sc.mesh.num_objects())
            .member("vertices", sc.mesh.num_vertices())
            .member("tets", sc.mesh.num_tets())
            .key("mean_edge")
            .number_text(fmt_double(sc.mean_edge))
            .end_object();
    j.end_array().key("notes").begin_array();
    for (const auto& n : plan.notes)
        j.value(n);
    j.end_array().key("summary");
    write_summary(j, table);
    j.end_object();
    write_json_file(res.json_path, j);
}

std::vector<std::int64_t> merge_studies(const std::vector<std::string>& dirs, const std::string& out_dir,
                                        const std::string& command_line)
{
    if (dirs.empty()) throw Error("study merge: no input folders");
    for (const auto& d : dirs)
        if (!fs::exists(fs::path(d) / "study.csv"))
            throw Error("study merge: " + (fs::path(d) / "study.csv").string() + ": file not found");
    Table merged;
    std::vector<std::string> jsons; // each shard's study.json, checked to be JSON, embedded as it is
    long long total = -1;
    std::string sweep = "?";
    for (const auto& d : dirs) {
        const std::string csv = (fs::path(d) / "study.csv").string();
        Table t = Table::read_csv(csv);
        if (merged.columns.empty()) {
            merged.columns = t.columns;
        } else if (t.columns != merged.columns) {
            throw Error("study merge: " + csv + ": columns differ from " +
                        (fs::path(dirs.front()) / "study.csv").string());
        }
        for (auto& r : t.rows)
            merged.rows.push_back(std::move(r));
        const auto json_path = fs::path(d) / "study.json";
        if (!fs::exists(json_path)) continue;
        std::string text = read_file_text(json_path.string());
        const JsonValue shard = parse_json(text, "study merge: " + json_path.string());
        if (const JsonValue* n = shard.find("points_total"); n && n->kind == JsonValue::number && n->num >= 0)
            total = std::max(total, static_cast<long long>(n->num));
        if (const JsonValue* s = shard.find("sweep"); s && s->kind == JsonValue::string) sweep = s->text;
        while (!text.empty() && (text.back() == '\n' || text.back() == '\r' || text.back() == ' '))
            text.pop_back();
        jsons.push_back(std::move(text));
    }
    const int ip = merged.index_of("point"), ir = merged.index_of("repeat");
    if (ip < 0 || ir < 0) throw Error("study merge: the CSV files have no 'point' and 'repeat' columns");
    auto key = [&](const Row& r) {
        return std::pair<long long, long long>(std::atoll(r[static_cast<std::size_t>(ip)].c_str()),
                                               std::atoll(r[static_cast<std::size_t>(ir)].c_str()));
    };
    std::stable_sort(merged.rows.begin(), merged.rows.end(),
                     [&](const Row& a, const Row& b) { return key(a) < key(b); });
    for (std::size_t i = 1; i < merged.rows.size(); ++i)
        if (key(merged.rows[i]) == key(merged.rows[i - 1]))
            throw Error("study merge: point " + std::to_string(key(merged.rows[i]).first) + " repeat " +
                        std::to_string(key(merged.rows[i]).second) + " appears twice (the same shard given twice?)");
    std::vector<std::int64_t> missing;
    if (total >= 0) {
        std::vector<char> seen(static_cast<std::size_t>(total), 0);
        for (const Row& r : merged.rows) {
            const long long p = key(r).first;
            if (p >= 0 && p < total) seen[static_cast<std::size_t>(p)] = 1;
        }
        for (long long p = 0; p < total; ++p)
            if (!seen[static_cast<std::size_t>(p)]) missing.push_back(p);
    }
    check_out_dir(out_dir);
    make_out_dir(out_dir);
    merged.write_csv((fs::path(out_dir) / "study.csv").string());

    JsonWriter j;
    j.begin_object().member("tethash_study", 1).member("sweep", sweep).member("command", command_line);
    j.key("merged_from").begin_array();
    for (const auto& d : dirs)
        j.value(d);
    j.end_array().member("points_total", total).member("rows", merged.rows.size());
    j.key("missing_points").begin_array();
    for (const std::int64_t p : missing)
        j.value(p);
    j.end_array().key("shards").begin_array(JsonWriter::block_layout);
    for (const auto& text : jsons)
        j.raw(text);
    j.end_array().key("summary");
    write_summary(j, merged);
    j.end_object();
    write_json_file((fs::path(out_dir) / "study.json").string(), j);
    return missing;
}

} // namespace tethash::study
