// ParaView collections (.pvd): a list of (time, file) entries.
#include "tethash/io/pvd.hpp"

#include "number.hpp"
#include "tethash/error.hpp"
#include "tethash/io/file.hpp"
#include "xml.hpp"

#include <cmath>

namespace tethash::io {

void write_pvd(const std::string& path, const std::vector<std::pair<double, std::string>>& entries)
{
    std::vector<PvdEntry> parts;
    parts.reserve(entries.size());
    for (const auto& [time, file] : entries)
        parts.push_back({time, file, 0});
    write_pvd_parts(path, parts);
}

void write_pvd_parts(const std::string& path, const std::vector<PvdEntry>& entries)
{
    std::string xml = "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\" "
                      "byte_order=\"LittleEndian\">\n  <Collection>\n";
    for (const auto& [time, file, part] : entries) {
        if (!std::isfinite(time))
            throw Error(path + ": time " + detail::format_double(time) + " of '" + file + "' is not finite");
        if (file.empty())
            throw Error(path + ": an entry at time " + detail::format_double(time) + " has an empty file name");
        xml += "    <DataSet timestep=\"" + detail::format_double(time) + "\" group=\"\" part=\"" +
               std::to_string(part) + "\" file=\"" + detail::xml_escape(file) + "\"/>\n";
    }
    xml += "  </Collection>\n</VTKFile>\n";
    write_text_file(path, xml);
}

std::vector<std::pair<double, std::string>> read_pvd(const std::string& path)
{
    std::vector<std::pair<double, std::string>> r;
    for (PvdEntry& e : read_pvd_parts(path))
        r.emplace_back(e.time, std::move(e.file));
    return r;
}

std::vector<PvdEntry> read_pvd_parts(const std::string& path)
{
    const std::string data = read_file(path);
    const detail::XmlDocument doc = detail::parse_xml(path, data);
    const auto at = [&](std::int64_t line) { return path + ":" + std::to_string(line); };
    if (doc.root.name != "VTKFile")
        throw Error(at(doc.root.line) + ": expected <VTKFile>, found <" + doc.root.name + ">");
    const std::string* type = doc.root.attr("type");
    if (!type || *type != "Collection")
        throw Error(at(doc.root.line) + ": expected type=\"Collection\", found \"" + (type ? *type : std::string()) +
                    "\"");
    const detail::XmlElement* col = doc.root.child("Collection");
    if (!col) throw Error(at(doc.root.line) + ": expected <Collection>, found none");
    std::vector<PvdEntry> r;
    for (const auto& ds : col->children) {
        if (ds.name != "DataSet") continue;
        const std::string* file = ds.attr("file");
        if (!file) throw Error(at(ds.line) + ": expected attribute file=\"...\" in <DataSet>, found none");
        const std::string* ts = ds.attr("timestep");
        double t = 0;
        if (ts) {
            const auto v = detail::parse_double(*ts);
            if (!v || !std::isfinite(*v))
                throw Error(at(ds.line) + ": expected a number for timestep, found \"" + *ts + "\"");
            t = *v;
        }
        int part = 0;
        if (const std::string* p = ds.attr("part")) {
            const auto v = detail::parse_int(*p);
            if (!v || *v < 0 || *v > 1000000)
                throw Error(at(ds.line) + ": expected a part number for part, found \"" + *p + "\"");
            part = static_cast<int>(*v);
        }
        r.push_back({t, *file, part});
    }
    return r;
}

} // namespace tethash::io
