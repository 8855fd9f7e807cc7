#include "xml.hpp"

#include "vtk_detail.hpp"

#include "tethash/error.hpp"

#include <cctype>
#include <cstdlib>

namespace tethash::io::detail {

bool is_xml_space(char c)
{
    return c == ' ' || c == '\t' || c == '\n' || c == '\r';
}

std::string xml_escape(std::string_view s)
{
    std::string r;
    for (char c : s) {
        switch (c) {
        case '&':
            r += "&amp;";
            break;
        case '<':
            r += "&lt;";
            break;
        case '>':
            r += "&gt;";
            break;
        case '"':
            r += "&quot;";
            break;
        case '\'':
            r += "&apos;";
            break;
        default:
            r += c;
        }
    }
    return r;
}

namespace {

using vtk_detail::quote_token;

/// Deepest element nesting the parser accepts (VTK files use fewer than ten levels).
constexpr std::size_t k_max_xml_depth = 256;

class XmlParser {
  public:
    XmlParser(const std::string& path, const std::string& data) : m_path(path), m_data(data) {}
    XmlDocument parse();

  private:
    [[noreturn]] void fail(const std::string& msg) const
    {
        throw Error(m_path + ":" + std::to_string(m_line) + ": " + msg);
    }
    std::string found() const
    {
        if (m_pos >= m_data.size()) return "end of file";
        return quote_token(std::string_view(m_data).substr(m_pos, 16));
    }
    void advance_to(std::size_t p)
    {
        for (; m_pos < p; ++m_pos)
            if (m_data[m_pos] == '\n') ++m_line;
    }
    void skip_ws()
    {
        while (m_pos < m_data.size() && is_xml_space(m_data[m_pos])) {
            if (m_data[m_pos] == '\n') ++m_line;
            ++m_pos;
        }
    }
    bool starts(std::string_view s) const { return std::string_view(m_data).substr(m_pos, s.size()) == s; }
    void skip_past(std::string_view end, const char* what)
    {
        const std::size_t p = m_data.find(end, m_pos);
        if (p == std::string::npos)
            fail("expected '" + std::string(end) + "' to close " + what + ", found end of file");
        advance_to(p + end.size());
    }
    std::string name()
    {
        const std::size_t s = m_pos;
        while (m_pos < m_data.size()) {
            const unsigned char c = static_cast<unsigned char>(m_data[m_pos]);
            if (std::isalnum(c) || c == '_' || c == ':' || c == '.' || c == '-' || c >= 128)
                ++m_pos;
            else
                break;
        }
        return m_data.substr(s, m_pos - s);
    }
    std::string decode_entities(std::string_view v) const;

    const std::string& m_path;
    const std::string& m_data;
    std::size_t m_pos = 0;
    std::int64_t m_line = 1;
};

std::string XmlParser::decode_entities(std::string_view v) const
{
    std::string r;
    for (std::size_t i = 0; i < v.size(); ++i) {
        if (v[i] != '&') {
            r += v[i];
            continue;
        }
        const std::size_t semi = v.find(';', i);
        if (semi == std::string_view::npos) {
            r += v[i];
            continue;
        }
        const std::string_view ent = v.substr(i + 1, semi - i - 1);
        if (ent == "amp")
            r += '&';
        else if (ent == "lt")
            r += '<';
        else if (ent == "gt")
            r += '>';
        else if (ent == "quot")
            r += '"';
        else if (ent == "apos")
            r += '\'';
        else if (!ent.empty() && ent[0] == '#') {
            const bool hex = ent.size() > 1 && (ent[1] == 'x' || ent[1] == 'X');
            const unsigned long code =
                std::strtoul(std::string(ent.substr(hex ? 2 : 1)).c_str(), nullptr, hex ? 16 : 10);
            r += code < 128 ? static_cast<char>(code) : '?';
        } else {
            r += std::string(v.substr(i, semi - i + 1));
        }
        i = semi;
    }
    return r;
}

XmlDocument XmlParser::parse()
{
    XmlDocument doc;
    std::vector<XmlElement*> stack;
    bool have_root = false;
    for (;;) {
        const std::size_t lt = m_data.find('<', m_pos);
        if (lt == std::string::npos) {
            if (!stack.empty()) {
                advance_to(m_data.size());
                if (!m_data.empty() && m_data.back() == '\n' && m_line > 1)
                    --m_line; // the last line, not the empty one after it
                fail("expected </" + stack.back()->name + ">, found end of file");
            }
            break;
        }
        if (!stack.empty() && lt > m_pos) {
            stack.back()->text.emplace_back(m_pos, lt);
            stack.back()->text_line.push_back(m_line);
        }
        advance_to(lt);
        if (starts("<?")) {
            skip_past("?>", "a processing instruction");
        } else if (starts("<!--")) {
            skip_past("-->", "a comment");
        } else if (starts("<![CDATA[")) {
            const std::size_t b = m_pos + 9;
            const std::int64_t line = m_line;
            skip_past("]]>", "a CDATA section");
            if (!stack.empty()) {
                stack.back()->text.emplace_back(b, m_pos - 3);
                stack.back()->text_line.push_back(line);
            }
        } else if (starts("<!")) {
            skip_past(">", "a declaration");
        } else if (starts("</")) {
            m_pos += 2;
            const std::string n = name();
            skip_ws();
            if (m_pos >= m_data.size() || m_data[m_pos] != '>')
                fail("expected '>' after </" + n + ", found " + found());
            ++m_pos;
            if (stack.empty() || stack.back()->name != n)
                fail("expected " + (stack.empty() ? std::string("no end tag") : "</" + stack.back()->name + ">") +
                     ", found </" + n + ">");
            stack.pop_back();
            if (stack.empty()) break;
        } else {
            ++m_pos;
            XmlElement el;
            el.line = m_line;
            el.name = name();
            if (el.name.empty()) fail("expected an element name after '<', found " + found());
            bool empty = false;
            for (;;) {
                skip_ws();
                if (m_pos >= m_data.size()) fail("expected '>' to close <" + el.name + ", found end of file");
                if (starts("/>")) {
                    m_pos += 2;
                    empty = true;
                    break;
                }
                if (m_data[m_pos] == '>') {
                    ++m_pos;
                    break;
                }
                const std::string key = name();
                if (key.empty()) fail("expected an attribute name or '>' in <" + el.name + ">, found " + found());
                skip_ws();
                if (m_pos >= m_data.size() || m_data[m_pos] != '=')
                    fail("expected '=' after attribute " + key + " of <" + el.name + ">, found " + found());
                ++m_pos;
                skip_ws();
                if (m_pos >= m_data.size() || (m_data[m_pos] != '"' && m_data[m_pos] != '\''))
                    fail("expected a quoted value for attribute " + key + " of <" + el.name + ">, found " + found());
                const char q = m_data[m_pos++];
                const std::size_t end = m_data.find(q, m_pos);
                if (end == std::string::npos)
                    fail("expected the closing quote of attribute " + key + " of <" + el.name + ">, found end of file");
                el.attrs.emplace_back(key, decode_entities(std::string_view(m_data).substr(m_pos, end - m_pos)));
                advance_to(end + 1);
            }
            if (el.name == "AppendedData") {
                if (stack.empty()) fail("expected <VTKFile> before <AppendedData>");
                const std::string* enc = el.attr("encoding");
                doc.appended_encoding = enc ? *enc : "";
                doc.appended_line = el.line;
                if (!empty) {
                    skip_ws();
                    if (m_pos >= m_data.size() || m_data[m_pos] != '_')
                        fail("expected '_' at the start of the appended data, found " + found());
                    doc.appended_pos = m_pos + 1;
                }
                stack.back()->children.push_back(std::move(el));
                break; // the rest is (possibly binary) appended data
            }
            XmlElement* added;
            if (stack.empty()) {
                if (have_root) fail("expected a single root element, found a second one <" + el.name + ">");
                doc.root = std::move(el);
                have_root = true;
                added = &doc.root;
            } else {
                stack.back()->children.push_back(std::move(el));
                added = &stack.back()->children.back();
            }
            if (!empty) {
                // VTK files nest a few levels; the limit keeps a hostile file from exhausting the
                // stack in the (recursive) destruction of the element tree.
                if (stack.size() >= k_max_xml_depth)
                    fail("expected at most " + std::to_string(k_max_xml_depth) + " nested elements, found <" +
                         added->name + "> nested deeper");
                stack.push_back(added);
            }
        }
    }
    if (!have_root) fail("expected an XML element, found " + found());
    return doc;
}

} // namespace

XmlDocument parse_xml(const std::string& path, const std::string& data)
{
    return XmlParser(path, data).parse();
}

} // namespace tethash::io::detail
