// The JSON writer (json.hpp).
#include "tethash/study/json.hpp"

#include <charconv>
#include <cmath>
#include <cstdio>
#include <stdexcept>

namespace tethash::study {

std::string json_quote(std::string_view s)
{
    std::string o = "\"";
    for (const char ch : s) {
        const auto c = static_cast<unsigned char>(ch);
        switch (c) {
        case '"':
            o += "\\\"";
            break;
        case '\\':
            o += "\\\\";
            break;
        case '\n':
            o += "\\n";
            break;
        case '\r':
            o += "\\r";
            break;
        case '\t':
            o += "\\t";
            break;
        case '\b':
            o += "\\b";
            break;
        case '\f':
            o += "\\f";
            break;
        default:
            if (c < 0x20 || c == 0x7f) {
                char buf[8];
                std::snprintf(buf, sizeof buf, "\\u%04x", c);
                o += buf;
            } else {
                o += ch;
            }
        }
    }
    return o + "\"";
}

std::string json_number(double v)
{
    if (!std::isfinite(v)) return "null";
    char buf[32];
    const auto r = std::to_chars(buf, buf + sizeof buf, v); // shortest text that reads back as v
    return std::string(buf, r.ptr);
}

bool is_json_number(std::string_view t)
{
    std::size_t i = 0;
    const auto digits = [&] {
        const std::size_t from = i;
        while (i < t.size() && t[i] >= '0' && t[i] <= '9')
            ++i;
        return i - from;
    };
    if (i < t.size() && t[i] == '-') ++i;
    if (i < t.size() && t[i] == '0') {
        ++i;
    } else if (digits() == 0) {
        return false;
    }
    if (i < t.size() && t[i] == '.') {
        ++i;
        if (digits() == 0) return false;
    }
    if (i < t.size() && (t[i] == 'e' || t[i] == 'E')) {
        ++i;
        if (i < t.size() && (t[i] == '+' || t[i] == '-')) ++i;
        if (digits() == 0) return false;
    }
    return i == t.size();
}

void JsonWriter::newline(std::size_t depth)
{
    m_out += '\n';
    m_out.append(2 * depth, ' ');
}

void JsonWriter::before_value()
{
    if (m_done) throw std::logic_error("JsonWriter: a value after the end of the document");
    if (m_levels.empty()) return;
    Level& l = m_levels.back();
    if (l.object) {
        if (!m_after_key) throw std::logic_error("JsonWriter: a value inside an object needs a key first");
        m_after_key = false;
        return;
    }
    if (l.members++) m_out += l.block ? "," : ", ";
    if (l.block) newline(m_levels.size());
}

JsonWriter& JsonWriter::key(std::string_view name)
{
    if (m_levels.empty() || !m_levels.back().object || m_after_key)
        throw std::logic_error("JsonWriter: a key outside an object or after another key");
    Level& l = m_levels.back();
    if (l.members++) m_out += l.block ? "," : ", ";
    if (l.block) newline(m_levels.size());
    m_out += json_quote(name);
    m_out += ": ";
    m_after_key = true;
    return *this;
}

void JsonWriter::open(bool object, Layout layout)
{
    before_value();
    const bool block = layout == block_layout && (m_levels.empty() || m_levels.back().block);
    m_levels.push_back({object, block, 0});
    m_out += object ? '{' : '[';
}

JsonWriter& JsonWriter::begin_object(Layout layout)
{
    open(true, layout);
    return *this;
}

JsonWriter& JsonWriter::begin_array(Layout layout)
{
    open(false, layout);
    return *this;
}

void JsonWriter::close(bool object)
{
    if (m_levels.empty() || m_levels.back().object != object || m_after_key)
        throw std::logic_error(object ? "JsonWriter: end_object without its begin_object"
                                      : "JsonWriter: end_array without its begin_array");
    const Level l = m_levels.back();
    m_levels.pop_back();
    if (l.block && l.members) newline(m_levels.size());
    m_out += object ? '}' : ']';
    if (m_levels.empty()) m_done = true;
}

JsonWriter& JsonWriter::end_object()
{
    close(true);
    return *this;
}

JsonWriter& JsonWriter::end_array()
{
    close(false);
    return *this;
}

JsonWriter& JsonWriter::raw(std::string_view json)
{
    before_value();
    m_out += json;
    if (m_levels.empty()) m_done = true;
    return *this;
}

JsonWriter& JsonWriter::value(std::string_view s)
{
    return raw(json_quote(s));
}

JsonWriter& JsonWriter::value(double v)
{
    return raw(json_number(v));
}

JsonWriter& JsonWriter::value(bool v)
{
    return raw(v ? "true" : "false");
}

JsonWriter& JsonWriter::null()
{
    return raw("null");
}

JsonWriter& JsonWriter::number_text(std::string_view text)
{
    if (text.empty()) return null();
    return is_json_number(text) ? raw(text) : value(text);
}

const std::string& JsonWriter::str() const
{
    if (!m_levels.empty()) throw std::logic_error("JsonWriter: str() with a container still open");
    return m_out;
}

} // namespace tethash::study
