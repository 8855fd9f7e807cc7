// `tethash simulate --ccd-queries DIR` (simulate_ccd.hpp).
#include "simulate_ccd.hpp"

#include "tethash/ccd.hpp"
#include "tethash/continuous.hpp"
#include "tethash/error.hpp"
#include "tethash/io/file.hpp"

#include <fmt/format.h>

#include <cstdio>
#include <filesystem>
#include <string>

namespace tethash::cli {
namespace {

std::string path_in(const std::string& dir, const char* name)
{
    return (std::filesystem::path(dir) / name).string();
}

/// A positive step number of --ccd-steps.
int step_number(const std::string& text, const std::string& whole)
{
    std::size_t used = 0;
    long long v = 0;
    try {
        v = std::stoll(text, &used);
    } catch (const std::exception&) {
        used = 0;
    }
    if (used == 0 || used != text.size() || v < 1 || v > 2000000000)
        throw Error("--ccd-steps: expected a step number K or a range FIRST:LAST (1-based), found '" + whole + "'");
    return static_cast<int>(v);
}

} // namespace

CcdQueryRecorder::CcdQueryRecorder(const CcdQueryOptions& o) : m_dir(o.dir), m_max(o.max_queries)
{
    if (m_dir.empty()) {
        if (!o.steps.empty() || o.max_queries != CcdQueryOptions{}.max_queries)
            throw Error("--ccd-steps and --ccd-max-queries go with --ccd-queries DIR");
        return;
    }
    if (o.max_queries < 1) throw Error(fmt::format("--ccd-max-queries: expected at least 1, found {}", o.max_queries));
    if (!o.steps.empty()) {
        const auto colon = o.steps.find(':');
        m_first = step_number(o.steps.substr(0, colon), o.steps);
        m_last = colon == std::string::npos ? m_first : step_number(o.steps.substr(colon + 1), o.steps);
        if (m_last < m_first) throw Error("--ccd-steps: the last step comes before the first, found '" + o.steps + "'");
    }
    std::error_code ec;
    std::filesystem::create_directories(m_dir, ec);
    if (ec) {
        const std::string msg = "--ccd-queries: cannot create folder '" + m_dir + "': " + ec.message();
        if (ec == std::errc::not_a_directory || ec == std::errc::file_exists) throw Error(msg);
        throw WriteError(msg);
    }
    for (const char* name : {"vertex_face.csv", "edge_edge.csv"})
        io::check_output_file(path_in(m_dir, name), "--ccd-queries");
}

bool CcdQueryRecorder::wants(int step) const
{
    return on() && !m_capped && step >= m_first && (m_last == 0 || step <= m_last);
}

void CcdQueryRecorder::record(int step, const TetsRef& tets, const PositionsRef& x0, const PositionsRef& x1)
{
    if (!wants(step)) return;
    const ccd::ContinuousCandidates c = ccd::continuous_candidates(tets, x0, x1);
    if (static_cast<std::int64_t>(m_vertex_face.size() + c.vertex_face.size()) > m_max ||
        static_cast<std::int64_t>(m_edge_edge.size() + c.edge_edge.size()) > m_max) {
        m_capped = true;
        m_capped_at = step;
        return;
    }
    const auto point = [](const PositionsRef& x, Index v) { return Eigen::Vector3d(x.row(v).transpose()); };
    const ccd::CcdParams params;
    for (const auto& [v, f] : c.vertex_face) {
        io::CcdQuery q;
        const Index ids[4] = {v, c.faces(f, 0), c.faces(f, 1), c.faces(f, 2)};
        for (int k = 0; k < 4; ++k) {
            q.points[static_cast<std::size_t>(k)] = point(x0, ids[k]);
            q.points[static_cast<std::size_t>(k + 4)] = point(x1, ids[k]);
        }
        const auto& p = q.points;
        q.collides = ccd::vertex_face_ccd(p[0], p[1], p[2], p[3], p[4], p[5], p[6], p[7], params).hit;
        m_vertex_face.push_back(q);
    }
    for (const auto& [e, g] : c.edge_edge) {
        io::CcdQuery q;
        const Index ids[4] = {c.edges(e, 0), c.edges(e, 1), c.edges(g, 0), c.edges(g, 1)};
        for (int k = 0; k < 4; ++k) {
            q.points[static_cast<std::size_t>(k)] = point(x0, ids[k]);
            q.points[static_cast<std::size_t>(k + 4)] = point(x1, ids[k]);
        }
        const auto& p = q.points;
        q.collides = ccd::edge_edge_ccd(p[0], p[1], p[2], p[3], p[4], p[5], p[6], p[7], params).hit;
        m_edge_edge.push_back(q);
    }
    if (m_recorded_steps++ == 0) m_recorded_first = step;
    m_recorded_last = step;
}

void CcdQueryRecorder::write() const
{
    if (!on()) return;
    const std::string vf = path_in(m_dir, "vertex_face.csv"), ee = path_in(m_dir, "edge_edge.csv");
    io::write_ccd_queries(vf, m_vertex_face);
    try {
        io::write_ccd_queries(ee, m_edge_edge);
    } catch (...) {
        std::error_code ec;
        std::filesystem::remove(vf, ec); // both files or neither
        throw;
    }
    const auto colliding = [](const std::vector<io::CcdQuery>& qs) {
        std::int64_t n = 0;
        for (const auto& q : qs)
            n += q.collides;
        return n;
    };
    const std::string steps = m_recorded_steps == 0 ? std::string("no step")
                              : m_recorded_first == m_recorded_last
                                  ? fmt::format("step {}", m_recorded_first)
                                  : fmt::format("steps {}-{}", m_recorded_first, m_recorded_last);
    std::fprintf(stdout,
                 "ccd queries: %zu vertex-face (%lld colliding) in %s, %zu edge-edge (%lld colliding) in %s, of %s "
                 "(replay: tethash ccd FILE --type vertex-face|edge-edge)\n",
                 m_vertex_face.size(), static_cast<long long>(colliding(m_vertex_face)), vf.c_str(), m_edge_edge.size(),
                 static_cast<long long>(colliding(m_edge_edge)), ee.c_str(), steps.c_str());
    if (m_capped)
        std::fprintf(stderr,
                     "tethash: note: --ccd-queries: step %d and later left out: they would pass --ccd-max-queries "
                     "%lld in a file\n",
                     m_capped_at, static_cast<long long>(m_max));
}

} // namespace tethash::cli
