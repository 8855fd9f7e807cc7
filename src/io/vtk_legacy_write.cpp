// Legacy VTK (.vtk) UNSTRUCTURED_GRID writer (version 4.2, ASCII or big-endian binary).
#include "tethash/error.hpp"
#include "tethash/io/file.hpp"
#include "tethash/io/vtk_legacy.hpp"
#include "vtk_detail.hpp"
#include "vtk_labels.hpp"

#include <cmath>
#include <string>
#include <vector>

namespace tethash::io {
namespace {

using namespace vtk_detail;

void write_values(std::string& out, bool binary, bool integer, const double* d, const Index* ints, std::size_t count,
                  int per_line)
{
    for (std::size_t i = 0; i < count; ++i) {
        if (binary) {
            if (integer)
                append_bytes<std::int32_t>(out, ints[i], true);
            else
                append_bytes<double>(out, d[i], true);
        } else {
            out += integer ? std::to_string(ints[i]) : format_double(d[i]);
            out += (i + 1) % static_cast<std::size_t>(per_line) == 0 ? '\n' : ' ';
        }
    }
    if (binary || count % static_cast<std::size_t>(per_line) != 0) out += '\n';
}

void write_arrays(std::string& out, bool binary, const char* section, std::size_t count,
                  const std::vector<OutArray>& arrays)
{
    if (arrays.empty()) return;
    out += std::string(section) + " " + std::to_string(count) + "\n";
    out += "FIELD FieldData " + std::to_string(arrays.size()) + "\n";
    for (const OutArray& a : arrays) {
        out += a.name + " " + std::to_string(a.components) + " " + std::to_string(count) +
               (a.integer ? " int\n" : " double\n");
        write_values(out, binary, a.integer, a.values ? a.values->data() : nullptr, a.ints ? a.ints->data() : nullptr,
                     count * static_cast<std::size_t>(a.components), a.components);
    }
}

} // namespace

void write_vtk(const std::string& path, const TetMesh& mesh, const Fields& fields, bool binary)
{
    std::vector<OutArray> point_arrays, cell_arrays;
    collect_out_arrays(path, mesh, fields, false, point_arrays, cell_arrays);
    const std::size_t n = static_cast<std::size_t>(mesh.num_vertices()), m = static_cast<std::size_t>(mesh.num_tets());

    std::string out;
    out += "# vtk DataFile Version 4.2\n";
    out += "tethash tet mesh: " + std::to_string(n) + " vertices, " + std::to_string(m) + " tets\n";
    out += binary ? "BINARY\n" : "ASCII\n";
    out += "DATASET UNSTRUCTURED_GRID\n";
    out += "POINTS " + std::to_string(n) + " double\n";
    write_values(out, binary, false, mesh.positions.data(), nullptr, 3 * n, 3);
    out += "CELLS " + std::to_string(m) + " " + std::to_string(5 * m) + "\n";
    for (std::size_t t = 0; t < m; ++t) {
        if (binary) {
            append_bytes<std::int32_t>(out, 4, true);
            for (int k = 0; k < 4; ++k)
                append_bytes<std::int32_t>(out, mesh.tets(static_cast<Eigen::Index>(t), k), true);
        } else {
            out += "4";
            for (int k = 0; k < 4; ++k) {
                out += ' ';
                out += std::to_string(mesh.tets(static_cast<Eigen::Index>(t), k));
            }
            out += '\n';
        }
    }
    if (binary) out += '\n';
    out += "CELL_TYPES " + std::to_string(m) + "\n";
    for (std::size_t t = 0; t < m; ++t) {
        if (binary)
            append_bytes<std::int32_t>(out, 10, true);
        else
            out += "10\n";
    }
    if (binary) out += '\n';
    write_arrays(out, binary, "POINT_DATA", n, point_arrays);
    write_arrays(out, binary, "CELL_DATA", m, cell_arrays);

    write_text_file(path, out);
}

} // namespace tethash::io
