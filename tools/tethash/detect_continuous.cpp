// tethash detect --continuous FRAME0 FRAME1: boundary vertex-face and edge-edge contacts over the step from one
// frame to the next (linear motion), with their time of impact (tethash/continuous.hpp).
#include "detect_continuous.hpp"

#include "command.hpp"
#include "tethash/continuous.hpp"
#include "tethash/error.hpp"
#include "tethash/io/file.hpp"
#include "tethash/io/mesh_io.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>

namespace tethash::cli {
namespace {

/// Contacts as CSV: a header comment saying which column is which, then one row per contact.
std::string continuous_csv(const ccd::ContinuousResult& r, const std::vector<ccd::ContinuousContact>& contacts,
                           const std::vector<Index>& vertex_object, const ContinuousOptions& o)
{
    std::string csv = "# tethash detect --continuous: each row is a pair of boundary primitives that may meet during "
                      "the step from frame 0 to frame 1 (linear motion).\n"
                      "# kind: vertex-face (a0 the vertex, b0..b2 the face's corners, outward) or edge-edge (a0, a1 "
                      "and b0, b1 the edges' ends); 0-based vertex ids of the frames.\n"
                      "# a_object, b_object: the objects of a0 and b0; toi: a time in [0, 1] no later than the "
                      "pair's first contact (0 = frame 0, 1 = frame 1).\n";
    csv += fmt::format("# frame 0: {}\n# frame 1: {}\n", o.frame0, o.frame1);
    csv += "kind,a0,a1,b0,b1,b2,a_object,b_object,toi\n";
    for (const auto& c : contacts) {
        const auto obj = [&](Index v) { return vertex_object[static_cast<std::size_t>(v)]; };
        if (c.kind == ccd::ContinuousKind::vertex_face) {
            const auto f = r.faces.row(c.b);
            csv += fmt::format("vertex-face,{},,{},{},{},{},{},{:.17g}\n", c.a, f(0), f(1), f(2), obj(c.a), obj(f(0)),
                               c.toi);
        } else {
            const auto a = r.edges.row(c.a), b = r.edges.row(c.b);
            csv += fmt::format("edge-edge,{},{},{},{},,{},{},{:.17g}\n", a(0), a(1), b(0), b(1), obj(a(0)), obj(b(0)),
                               c.toi);
        }
    }
    return csv;
}

} // namespace

void run_continuous(const ContinuousOptions& o)
{
    if (!o.contacts_path.empty()) {
        io::check_output_file(o.contacts_path, "--contacts");
        if (io::extension_of(o.contacts_path) != ".csv")
            throw Error("--contacts " + o.contacts_path + ": with --continuous the contacts are written as .csv");
    }
    io::ReadOptions read_options;
    read_options.linearize = o.linearize;
    TetMesh m0 = io::read_tet_mesh(o.frame0, nullptr, read_options);
    const TetMesh m1 = io::read_tet_mesh(o.frame1, nullptr, read_options);
    if (m1.num_vertices() != m0.num_vertices() || m1.num_tets() != m0.num_tets() || m1.tets != m0.tets)
        throw Error(fmt::format("--continuous: {} has {} vertices and {} tets, {} has {} and {}{}: the two frames must "
                                "be the same meshes",
                                o.frame1, m1.num_vertices(), m1.num_tets(), o.frame0, m0.num_vertices(), m0.num_tets(),
                                m1.num_tets() == m0.num_tets() && m1.num_vertices() == m0.num_vertices()
                                    ? " (the same counts, other tets)"
                                    : ""));
    if (!o.objects_from_labels.empty()) {
        fmt::print("{}: {}\n", o.frame0, objects_from_labels(m0, o.frame0, o.objects_from_labels));
    } else if (!(!m0.tet_object.empty() && m0.num_objects() > 1)) {
        m0.vertex_object.clear();
        m0.tet_object.clear();
    }
    m0.ensure_object_ids();
    const Index num_objects = std::max<Index>(1, m0.num_objects());
    std::vector<char> is_static(static_cast<std::size_t>(num_objects), 0);
    for (const int s : o.static_objects) {
        if (s < 0 || s >= num_objects)
            throw Error(fmt::format("--static: object {} out of range [0, {}) (the frame's objects)", s, num_objects));
        is_static[static_cast<std::size_t>(s)] = 1;
    }
    ccd::ContinuousParams params;
    params.threads = o.threads;
    const auto start = std::chrono::steady_clock::now();
    const ccd::ContinuousResult r = ccd::detect_continuous(m0.tets, m0.positions, m1.positions, params);
    const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();

    const auto first_vertex = [&](const ccd::ContinuousContact& c, bool side_a) {
        if (c.kind == ccd::ContinuousKind::vertex_face) return side_a ? c.a : r.faces(c.b, 0);
        return side_a ? r.edges(c.a, 0) : r.edges(c.b, 0);
    };
    std::vector<ccd::ContinuousContact> kept;
    std::int64_t vertex_face = 0;
    double earliest = 1;
    for (const auto& c : r.contacts) {
        const Index oa = m0.vertex_object[static_cast<std::size_t>(first_vertex(c, true))];
        const Index ob = m0.vertex_object[static_cast<std::size_t>(first_vertex(c, false))];
        if (o.no_self && oa == ob) continue;
        if (is_static[static_cast<std::size_t>(oa)] && is_static[static_cast<std::size_t>(ob)]) continue;
        kept.push_back(c);
        vertex_face += c.kind == ccd::ContinuousKind::vertex_face;
        earliest = std::min(earliest, c.toi);
    }
    fmt::print("scene: {} objects, {} vertices, {} tets; boundary: {} faces, {} edges\n", num_objects,
               m0.num_vertices(), m0.num_tets(), r.faces.rows(), r.edges.rows());
    fmt::print("continuous: {} vertex-face and {} edge-edge candidates (swept boxes overlap), {:.3f} ms\n",
               r.vertex_face_candidates, r.edge_edge_candidates, ms);
    if (kept.empty())
        fmt::print("contacts: 0\n");
    else
        fmt::print("contacts: {} ({} vertex-face, {} edge-edge), earliest time of impact {:.9g}\n", kept.size(),
                   vertex_face, static_cast<std::int64_t>(kept.size()) - vertex_face, earliest);
    if (!o.contacts_path.empty()) io::write_text_file(o.contacts_path, continuous_csv(r, kept, m0.vertex_object, o));
}

} // namespace tethash::cli
