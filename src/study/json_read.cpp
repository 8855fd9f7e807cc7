// The JSON reader (json_read.hpp): recursive descent over the grammar of RFC 8259.
#include "json_read.hpp"

#include "tethash/error.hpp"
#include "tethash/study/json.hpp"

#include <cstdlib>

namespace tethash::study {

const JsonValue* JsonValue::find(std::string_view name) const
{
    const JsonValue* found = nullptr;
    for (const auto& [k, v] : members) // name, value
        if (k == name) found = &v;
    return found;
}

namespace {

class Parser {
  public:
    Parser(std::string_view text, const std::string& what) : m_text(text), m_what(what) {}

    JsonValue document()
    {
        JsonValue v = value(0);
        space();
        if (m_pos != m_text.size()) fail("text after the end of the document");
        return v;
    }

  private:
    [[noreturn]] void fail(const std::string& message) const
    {
        std::size_t line = 1;
        for (std::size_t i = 0; i < m_pos && i < m_text.size(); ++i)
            line += m_text[i] == '\n';
        throw Error(m_what + ": invalid JSON at line " + std::to_string(line) + ": " + message);
    }

    void space()
    {
        while (m_pos < m_text.size() &&
               (m_text[m_pos] == ' ' || m_text[m_pos] == '\t' || m_text[m_pos] == '\n' || m_text[m_pos] == '\r'))
            ++m_pos;
    }

    bool eat(char c)
    {
        space();
        if (m_pos < m_text.size() && m_text[m_pos] == c) {
            ++m_pos;
            return true;
        }
        return false;
    }

    bool word(std::string_view w)
    {
        if (m_text.substr(m_pos, w.size()) != w) return false;
        m_pos += w.size();
        return true;
    }

    JsonValue value(int depth)
    {
        if (depth > 256) fail("nested too deeply");
        space();
        if (m_pos == m_text.size()) fail("unexpected end of the text");
        JsonValue v;
        const char c = m_text[m_pos];
        if (c == '{') {
            ++m_pos;
            v.kind = JsonValue::object;
            if (eat('}')) return v;
            do {
                space();
                if (m_pos == m_text.size() || m_text[m_pos] != '"') fail("expected a member name");
                std::string name = string();
                if (!eat(':')) fail("expected ':' after a member name");
                v.members.push_back(JsonMember{std::move(name), value(depth + 1)});
            } while (eat(','));
            if (!eat('}')) fail("expected ',' or '}'");
        } else if (c == '[') {
            ++m_pos;
            v.kind = JsonValue::array;
            if (eat(']')) return v;
            do
                v.items.push_back(value(depth + 1));
            while (eat(','));
            if (!eat(']')) fail("expected ',' or ']'");
        } else if (c == '"') {
            v.kind = JsonValue::string;
            v.text = string();
        } else if (word("true") || word("false")) {
            v.kind = JsonValue::boolean;
            v.flag = c == 't';
        } else if (word("null")) {
            v.kind = JsonValue::null;
        } else {
            std::size_t end = m_pos;
            while (end < m_text.size() &&
                   std::string_view("+-0123456789.eE").find(m_text[end]) != std::string_view::npos)
                ++end;
            v.text = std::string(m_text.substr(m_pos, end - m_pos));
            if (!is_json_number(v.text)) fail("unexpected '" + std::string(1, c) + "'");
            v.kind = JsonValue::number;
            v.num = std::strtod(v.text.c_str(), nullptr);
            m_pos = end;
        }
        return v;
    }

    unsigned hex4()
    {
        if (m_pos + 4 > m_text.size()) fail("short \\u escape");
        unsigned u = 0;
        for (int k = 0; k < 4; ++k) {
            const char h = m_text[m_pos++];
            u <<= 4;
            if (h >= '0' && h <= '9')
                u |= static_cast<unsigned>(h - '0');
            else if (h >= 'a' && h <= 'f')
                u |= static_cast<unsigned>(h - 'a' + 10);
            else if (h >= 'A' && h <= 'F')
                u |= static_cast<unsigned>(h - 'A' + 10);
            else
                fail("bad \\u escape");
        }
        return u;
    }

    static void utf8(unsigned cp, std::string& out)
    {
        if (cp < 0x80) {
            out += static_cast<char>(cp);
        } else if (cp < 0x800) {
            out += static_cast<char>(0xc0 | (cp >> 6));
            out += static_cast<char>(0x80 | (cp & 0x3f));
        } else if (cp < 0x10000) {
            out += static_cast<char>(0xe0 | (cp >> 12));
            out += static_cast<char>(0x80 | ((cp >> 6) & 0x3f));
            out += static_cast<char>(0x80 | (cp & 0x3f));
        } else {
            out += static_cast<char>(0xf0 | (cp >> 18));
            out += static_cast<char>(0x80 | ((cp >> 12) & 0x3f));
            out += static_cast<char>(0x80 | ((cp >> 6) & 0x3f));
            out += static_cast<char>(0x80 | (cp & 0x3f));
        }
    }

    std::string string()
    {
        ++m_pos; // the opening quote
        std::string out;
        for (;;) {
            if (m_pos >= m_text.size()) fail("unterminated string");
            const char c = m_text[m_pos++];
            if (c == '"') return out;
            if (static_cast<unsigned char>(c) < 0x20) fail("control character in a string");
            if (c != '\\') {
                out += c;
                continue;
            }
            if (m_pos >= m_text.size()) fail("unterminated string");
            switch (const char e = m_text[m_pos++]) {
            case '"':
            case '\\':
            case '/':
                out += e;
                break;
            case 'n':
                out += '\n';
                break;
            case 't':
                out += '\t';
                break;
            case 'r':
                out += '\r';
                break;
            case 'b':
                out += '\b';
                break;
            case 'f':
                out += '\f';
                break;
            case 'u': {
                unsigned cp = hex4();
                if (cp >= 0xd800 && cp < 0xdc00 && m_text.substr(m_pos, 2) == "\\u") {
                    m_pos += 2;
                    const unsigned lo = hex4();
                    if (lo < 0xdc00 || lo >= 0xe000) fail("unpaired surrogate in \\u escape");
                    cp = 0x10000 + ((cp - 0xd800) << 10) + (lo - 0xdc00);
                }
                utf8(cp, out);
                break;
            }
            default:
                fail(std::string("bad escape '\\") + e + "'");
            }
        }
    }

    std::string_view m_text;
    const std::string& m_what;
    std::size_t m_pos = 0;
};

} // namespace

JsonValue parse_json(std::string_view text, const std::string& what)
{
    return Parser(text, what).document();
}

} // namespace tethash::study
