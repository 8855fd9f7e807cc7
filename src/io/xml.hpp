#pragma once
// Private to tethash::io: a small XML reader for the VTK XML formats (.vtu, .pvd): elements,
// attributes and the byte ranges of their text, with line numbers for messages. It stops at
// <AppendedData>, whose (possibly binary) content the caller reads from the recorded offset.
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace tethash::io::detail {

struct XmlElement {
    std::string name;
    std::vector<std::pair<std::string, std::string>> attrs;
    std::vector<XmlElement> children;
    std::vector<std::pair<std::size_t, std::size_t>> text; ///< [begin, end) byte ranges of direct text
    std::vector<std::int64_t> text_line;                   ///< line at the start of each text range
    std::int64_t line = 0;

    const std::string* attr(std::string_view key) const
    {
        for (const auto& [k, v] : attrs)
            if (k == key) return &v;
        return nullptr;
    }
    const XmlElement* child(std::string_view n) const
    {
        for (const auto& c : children)
            if (c.name == n) return &c;
        return nullptr;
    }
};

struct XmlDocument {
    XmlElement root;
    std::size_t appended_pos = std::string::npos; ///< first byte after the '_' of <AppendedData>
    std::string appended_encoding;
    std::int64_t appended_line = 0;
};

/// Deepest element nesting the parser accepts (VTK files use fewer than ten levels).
constexpr std::size_t k_max_xml_depth = 256;

/// Parses `data` (the whole file `path`, named in messages). Throws Error "PATH:LINE: expected X,
/// found Y" on malformed XML or nesting deeper than 256 elements.
XmlDocument parse_xml(const std::string& path, const std::string& data);

/// `s` with & < > " ' written as entities, for attribute values.
std::string xml_escape(std::string_view s);

/// XML white space (space, tab, line feed, carriage return).
bool is_xml_space(char c);

} // namespace tethash::io::detail
