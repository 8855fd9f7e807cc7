#include "text_reader.hpp"

#include "number.hpp"
#include "tethash/io/file.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>

namespace tethash::io::detail {

TextReader::TextReader(std::string path, char comment, char extra_separator)
    : m_path(std::move(path)), m_comment(comment), m_extra(extra_separator)
{
    m_data = read_file(m_path);
}

TextReader::TextReader(std::string path, std::string content, char comment, char extra_separator)
    : m_path(std::move(path)), m_data(std::move(content)), m_comment(comment), m_extra(extra_separator)
{
}

void TextReader::skip_space()
{
    const std::size_t n = m_data.size();
    while (m_pos < n) {
        const char c = m_data[m_pos];
        if (c == '\n') {
            ++m_line;
            ++m_pos;
        } else if (is_space(c)) {
            ++m_pos;
        } else if (m_comment && c == m_comment) {
            while (m_pos < n && m_data[m_pos] != '\n')
                ++m_pos;
        } else {
            break;
        }
    }
}

bool TextReader::at_end()
{
    skip_space();
    return m_pos >= m_data.size();
}

std::string_view TextReader::peek()
{
    skip_space();
    std::size_t e = m_pos;
    while (e < m_data.size() && !is_space(m_data[e]) && !(m_comment && m_data[e] == m_comment))
        ++e;
    return std::string_view(m_data).substr(m_pos, e - m_pos);
}

std::int64_t TextReader::peek_line()
{
    skip_space();
    return m_line;
}

std::string_view TextReader::next(std::string_view what)
{
    const std::string_view tok = peek();
    m_token_line = m_line;
    if (tok.empty()) {
        // Name the last line of the file rather than the empty one after its final line break.
        if (m_token_line > 1 && !m_data.empty() && m_data.back() == '\n') --m_token_line;
        fail(what, "end of file");
    }
    m_pos += tok.size();
    return tok;
}

void TextReader::expect(std::string_view word, bool ignore_case)
{
    const std::string_view tok = next(word);
    const bool same =
        ignore_case ? (tok.size() == word.size() && std::equal(tok.begin(), tok.end(), word.begin(),
                                                               [](char a, char b) {
                                                                   return std::tolower(static_cast<unsigned char>(a)) ==
                                                                          std::tolower(static_cast<unsigned char>(b));
                                                               }))
                    : tok == word;
    if (!same) fail(word, describe(tok));
}

std::int64_t TextReader::next_int(std::string_view what)
{
    const std::string_view tok = next(what);
    const auto v = parse_int(tok);
    if (!v) fail(std::string(what) + " (an integer)", describe(tok));
    return *v;
}

void TextReader::check_count_fits(std::int64_t count, std::string_view items, std::string_view found_suffix) const
{
    if (count > static_cast<std::int64_t>(size()))
        fail("a number of " + std::string(items) + " that fits in a file of " + std::to_string(size()) + " bytes",
             std::to_string(count) + std::string(found_suffix));
}

std::int64_t TextReader::next_int_in(std::string_view what, std::int64_t lo, std::int64_t hi)
{
    const std::int64_t v = next_int(what);
    if (v < lo || v > hi)
        fail(std::string(what) + " in " + std::to_string(lo) + ".." + std::to_string(hi), std::to_string(v));
    return v;
}

double TextReader::next_double(std::string_view what)
{
    const std::string_view tok = next(what);
    const auto v = parse_double(tok);
    if (!v) fail(std::string(what) + " (a number)", describe(tok));
    if (!std::isfinite(*v)) fail(std::string(what) + " (a finite number)", describe(tok));
    return *v;
}

double TextReader::next_double_any(std::string_view what)
{
    const std::string_view tok = next(what);
    const auto v = parse_double(tok);
    if (!v) fail(std::string(what) + " (a number)", describe(tok));
    return *v;
}

void TextReader::skip_rest_of_line()
{
    while (m_pos < m_data.size() && m_data[m_pos] != '\n')
        ++m_pos;
    if (m_pos < m_data.size()) {
        ++m_pos;
        ++m_line;
    }
}

std::string_view TextReader::next_line(bool* eof)
{
    if (eof) *eof = m_pos >= m_data.size();
    m_token_line = m_line;
    const std::size_t start = m_pos;
    while (m_pos < m_data.size() && m_data[m_pos] != '\n')
        ++m_pos;
    std::size_t end = m_pos;
    if (m_pos < m_data.size()) {
        ++m_pos;
        ++m_line;
    }
    if (end > start && m_data[end - 1] == '\r') --end;
    return std::string_view(m_data).substr(start, end - start);
}

bool TextReader::skip_past_line(std::string_view marker)
{
    std::size_t from = m_pos;
    while (true) {
        const std::size_t hit = m_data.find(marker, from);
        if (hit == std::string::npos) return false;
        const bool line_start = hit == 0 || m_data[hit - 1] == '\n';
        std::size_t e = hit + marker.size();
        while (e < m_data.size() && (m_data[e] == ' ' || m_data[e] == '\t' || m_data[e] == '\r'))
            ++e;
        const bool line_end = e >= m_data.size() || m_data[e] == '\n';
        if (line_start && line_end) {
            m_line += std::count(m_data.begin() + static_cast<std::ptrdiff_t>(m_pos),
                                 m_data.begin() + static_cast<std::ptrdiff_t>(hit), '\n');
            m_token_line = m_line;
            m_pos = e;
            skip_rest_of_line();
            return true;
        }
        from = hit + 1;
    }
}

std::string TextReader::describe(std::string_view token)
{
    return token.empty() ? "end of file" : quote_token(token, 40);
}

void TextReader::fail(std::string_view expected, std::string_view found) const
{
    throw Error(m_path + ":" + std::to_string(m_token_line) + ": expected " + std::string(expected) + ", found " +
                std::string(found));
}

void TextReader::fail_message(const std::string& message) const
{
    fail_at_line(m_token_line, message);
}

void TextReader::fail_at_line(std::int64_t line, const std::string& message) const
{
    throw Error(m_path + ":" + std::to_string(line) + ": " + message);
}

void TextReader::fail_at_byte(std::size_t offset, const std::string& message) const
{
    throw Error(m_path + ": byte " + std::to_string(offset) + ": " + message);
}

std::uint64_t TextReader::read_binary_uint(std::size_t size, std::string_view what)
{
    if (size == 4) return read_binary<std::uint32_t>(what);
    return read_binary<std::uint64_t>(what);
}

void TextReader::skip_bytes(std::size_t count, std::string_view what)
{
    if (m_data.size() - m_pos < count)
        fail_at_byte(m_pos, "expected " + std::string(what) + " (" + std::to_string(count) +
                                " bytes), found end of file after " + std::to_string(m_data.size() - m_pos) + " bytes");
    m_pos += count;
}

} // namespace tethash::io::detail
