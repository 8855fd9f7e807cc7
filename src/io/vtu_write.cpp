// VTK XML UnstructuredGrid (.vtu) writer.
#include "tethash/io/vtu.hpp"

#include "number.hpp"
#include "tethash/error.hpp"
#include "tethash/io/file.hpp"
#include "vtk_detail.hpp"
#include "vtk_labels.hpp"
#include "xml.hpp"

#include <cmath>
#include <string>
#include <vector>

namespace tethash::io {

using namespace vtk_detail;
using detail::xml_escape;

namespace {

/// The cells of one kind (`nodes` per cell, VTK type `type`): `cells` holds m × nodes point ids, row-major.
void write_vtu_cells(const std::string& path, const Positions& positions, const Index* cells, std::size_t m, int nodes,
                     char type, const std::vector<OutArray>& point_arrays, const std::vector<OutArray>& cell_arrays)
{
    const std::size_t n = static_cast<std::size_t>(positions.rows()), k = static_cast<std::size_t>(nodes);
    const bool offsets64 = k * m > static_cast<std::size_t>(std::numeric_limits<std::int32_t>::max());
    // Every array as (XML attributes, byte size, writer of its little-endian data).
    struct Block {
        std::string section; // "PointData", "CellData", "Points", "Cells"
        std::string attrs;
        std::size_t bytes;
        std::function<void(std::string&)> write;
    };
    std::vector<Block> blocks;
    const auto add_fields = [&](const std::vector<OutArray>& arrays, const char* section, std::size_t count) {
        for (const OutArray& a : arrays) {
            const std::size_t values = count * static_cast<std::size_t>(a.components);
            std::string at = std::string("type=\"") + (a.integer ? "Int32" : "Float64") + "\" Name=\"" +
                             xml_escape(a.name) + "\" NumberOfComponents=\"" + std::to_string(a.components) + "\"";
            blocks.push_back({section, at, values * (a.integer ? 4 : 8), [a, values](std::string& out) {
                                  for (std::size_t i = 0; i < values; ++i) {
                                      if (a.integer)
                                          append_bytes<std::int32_t>(out, (*a.ints)[i], false);
                                      else
                                          append_bytes<double>(out, (*a.values)[i], false);
                                  }
                              }});
        }
    };
    add_fields(point_arrays, "PointData", n);
    add_fields(cell_arrays, "CellData", m);
    blocks.push_back(
        {"Points", "type=\"Float64\" Name=\"Points\" NumberOfComponents=\"3\"", 3 * n * 8, [&](std::string& out) {
             for (std::size_t i = 0; i < 3 * n; ++i)
                 append_bytes<double>(out, positions.data()[i], false);
         }});
    blocks.push_back({"Cells", "type=\"Int32\" Name=\"connectivity\"", k * m * 4, [&](std::string& out) {
                          for (std::size_t i = 0; i < k * m; ++i)
                              append_bytes<std::int32_t>(out, cells[i], false);
                      }});
    blocks.push_back({"Cells", std::string("type=\"") + (offsets64 ? "Int64" : "Int32") + "\" Name=\"offsets\"",
                      m * (offsets64 ? 8 : 4), [&](std::string& out) {
                          for (std::size_t t = 1; t <= m; ++t) {
                              if (offsets64)
                                  append_bytes<std::int64_t>(out, static_cast<std::int64_t>(k * t), false);
                              else
                                  append_bytes<std::int32_t>(out, static_cast<std::int32_t>(k * t), false);
                          }
                      }});
    blocks.push_back({"Cells", "type=\"UInt8\" Name=\"types\"", m, [&](std::string& out) { out.append(m, type); }});

    bool header64 = false;
    for (const Block& b : blocks)
        header64 = header64 || b.bytes > 0xffffffffu;
    const std::size_t hs = header64 ? 8 : 4;

    std::string xml = "<?xml version=\"1.0\"?>\n";
    xml +=
        std::string("<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"") +
        (header64 ? "UInt64" : "UInt32") + "\">\n";
    xml += "  <UnstructuredGrid>\n";
    xml += "    <Piece NumberOfPoints=\"" + std::to_string(n) + "\" NumberOfCells=\"" + std::to_string(m) + "\">\n";
    // The data go in reverse document order (the last DataArray at offset 0). VTK does not care;
    // meshio's raw-appended reader looks arrays up by offset after renumbering the ones it has
    // seen, and this order keeps a renumbered offset from shadowing one still to be read.
    std::size_t offset = 0;
    std::vector<std::size_t> offsets(blocks.size());
    for (std::size_t i = blocks.size(); i-- > 0;) {
        offsets[i] = offset;
        offset += hs + blocks[i].bytes;
    }
    for (const char* section : {"PointData", "CellData", "Points", "Cells"}) {
        bool any = false;
        for (std::size_t i = 0; i < blocks.size(); ++i) {
            if (blocks[i].section != section) continue;
            if (!any) xml += std::string("      <") + section + ">\n";
            any = true;
            xml += "        <DataArray " + blocks[i].attrs + " format=\"appended\" offset=\"" +
                   std::to_string(offsets[i]) + "\"/>\n";
        }
        if (any)
            xml += std::string("      </") + section + ">\n";
        else if (std::string(section) == "PointData" || std::string(section) == "CellData")
            xml += std::string("      <") + section + "/>\n";
    }
    xml += "    </Piece>\n  </UnstructuredGrid>\n  <AppendedData encoding=\"raw\">\n   _";
    xml.reserve(xml.size() + offset + 64);
    for (auto it = blocks.rbegin(); it != blocks.rend(); ++it) {
        const Block& b = *it;
        if (header64)
            append_bytes<std::uint64_t>(xml, b.bytes, false);
        else
            append_bytes<std::uint32_t>(xml, static_cast<std::uint32_t>(b.bytes), false);
        b.write(xml);
    }
    xml += "\n  </AppendedData>\n</VTKFile>\n";
    write_text_file(path, xml);
}

} // namespace

void write_vtu(const std::string& path, const TetMesh& mesh, const Fields& fields)
{
    std::vector<OutArray> point_arrays, cell_arrays;
    collect_out_arrays(path, mesh, fields, true, point_arrays, cell_arrays);
    write_vtu_cells(path, mesh.positions, mesh.tets.data(), static_cast<std::size_t>(mesh.num_tets()), 4, '\x0a',
                    point_arrays, cell_arrays);
}

void write_vtu_surface(const std::string& path, const meshing::SurfaceMesh& surface,
                       const std::vector<Index>& triangle_object)
{
    const Index n = static_cast<Index>(surface.vertices.rows());
    if (triangle_object.size() != static_cast<std::size_t>(surface.triangles.rows()))
        throw Error(path + ": " + std::to_string(triangle_object.size()) + " object ids for " +
                    std::to_string(surface.triangles.rows()) + " triangles");
    for (Index i = 0; i < 3 * static_cast<Index>(surface.triangles.rows()); ++i)
        if (surface.triangles.data()[i] < 0 || surface.triangles.data()[i] >= n)
            throw Error(path + ": triangle " + std::to_string(i / 3) + " refers to vertex " +
                        std::to_string(surface.triangles.data()[i]) + " of " + std::to_string(n));
    for (Index i = 0; i < 3 * n; ++i)
        if (!std::isfinite(surface.vertices.data()[i]))
            throw Error(path + ": vertex " + std::to_string(i / 3) + " has a non-finite coordinate");
    OutArray object;
    object.name = "object";
    object.integer = true;
    object.ints = &triangle_object;
    write_vtu_cells(path, surface.vertices, surface.triangles.data(),
                    static_cast<std::size_t>(surface.triangles.rows()), 3, '\x05', {}, {object});
}

} // namespace tethash::io
