#pragma once
/// \file text_reader.hpp
/// Internal to tethash::io: a tokenizer over a whole file held in memory that tracks line numbers
/// (for "FILE:LINE: expected X, found Y" messages) and can also read raw binary values at the current
/// byte offset (for formats that mix text and binary, such as binary Gmsh files).

#include "tethash/error.hpp"

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <string>
#include <string_view>
#include <utility>

namespace tethash::io::detail {

/// Whitespace-separated tokens with line numbers; optional end-of-line comments and extra separators.
class TextReader {
  public:
    /// Reads `path` whole. `comment`: a character that starts a comment running to the end of the line
    /// ('\0' for none). `extra_separator`: one more character treated as whitespace ('\0' for none).
    explicit TextReader(std::string path, char comment = '\0', char extra_separator = '\0');
    /// Reads from `content` instead of a file; `path` is used in messages only.
    TextReader(std::string path, std::string content, char comment = '\0', char extra_separator = '\0');

    const std::string& path() const { return m_path; }
    /// Line (1-based) of the last token read, or of the current position before any token.
    std::int64_t line() const { return m_token_line; }
    /// Current byte offset from the start of the file.
    std::size_t offset() const { return m_pos; }
    std::size_t size() const { return m_data.size(); }
    /// The bytes from the current offset to the end of the file (nothing is consumed).
    std::string_view rest() const { return std::string_view(m_data).substr(m_pos); }

    /// True when only whitespace and comments remain.
    bool at_end();
    /// The next token without consuming it ("" at the end of the file).
    std::string_view peek();
    /// Line of the token `peek()` would return.
    std::int64_t peek_line();
    /// The next token; throws "expected WHAT, found end of file" at the end.
    std::string_view next(std::string_view what);
    /// The next token, which must equal `word` (case-sensitive unless `ignore_case`).
    void expect(std::string_view word, bool ignore_case = false);
    /// The next token as an integer; throws "expected WHAT, found 'tok'" if it is not one.
    std::int64_t next_int(std::string_view what);
    /// The next token as an integer in [lo, hi].
    std::int64_t next_int_in(std::string_view what, std::int64_t lo, std::int64_t hi);
    /// Fails with "expected a number of ITEMS that fits in a file of N bytes, found COUNT`found_suffix`" when
    /// `count` items (each more than one byte) cannot be in the file: a broken header is not allocated for.
    void check_count_fits(std::int64_t count, std::string_view items, std::string_view found_suffix = "") const;
    /// The next token as a finite double (NaN and Inf are rejected).
    double next_double(std::string_view what);
    /// The next token as a double, NaN and Inf allowed.
    double next_double_any(std::string_view what);

    /// Consumes the rest of the current line including its line break.
    void skip_rest_of_line();
    /// Returns the rest of the current line (without "\r\n" or "\n") and moves past its line break;
    /// sets line() to that line. At the end of the file returns "" and `*eof` = true.
    std::string_view next_line(bool* eof = nullptr);

    /// Finds the next line that is exactly `marker` (trailing spaces and '\r' allowed), searching raw
    /// bytes (so it also works across binary data), and moves past it. Returns false if there is none.
    bool skip_past_line(std::string_view marker);

    /// Throws Error "PATH:LINE: expected WHAT, found FOUND" at the line of the last token.
    [[noreturn]] void fail(std::string_view expected, std::string_view found) const;
    /// Throws Error "PATH:LINE: MESSAGE".
    [[noreturn]] void fail_message(const std::string& message) const;
    /// Throws Error "PATH:LINE: MESSAGE" for a given line.
    [[noreturn]] void fail_at_line(std::int64_t line, const std::string& message) const;
    /// Throws Error "PATH: byte OFFSET: MESSAGE".
    [[noreturn]] void fail_at_byte(std::size_t offset, const std::string& message) const;

    /// How a token is shown in messages: quoted and shortened, or "end of file".
    static std::string describe(std::string_view token);

    // ---- binary data at the current offset -------------------------------------------------
    /// Byte-swap every multi-byte value read from now on.
    void set_swap_bytes(bool swap) { m_swap = swap; }
    bool swap_bytes() const { return m_swap; }
    /// Reads a value of type T (int32_t, uint32_t, uint64_t, double ...) at the current offset.
    template <class T> T read_binary(std::string_view what)
    {
        if (m_data.size() - m_pos < sizeof(T))
            fail_at_byte(m_pos, "expected " + std::string(what) + " (" + std::to_string(sizeof(T)) +
                                    " bytes), found end of file");
        unsigned char bytes[sizeof(T)];
        std::memcpy(bytes, m_data.data() + m_pos, sizeof(T));
        if (m_swap)
            for (std::size_t i = 0; i < sizeof(T) / 2; ++i)
                std::swap(bytes[i], bytes[sizeof(T) - 1 - i]);
        T value;
        std::memcpy(&value, bytes, sizeof(T));
        m_pos += sizeof(T);
        return value;
    }
    /// Reads an unsigned integer of `size` bytes (4 or 8).
    std::uint64_t read_binary_uint(std::size_t size, std::string_view what);
    /// Skips `count` bytes; throws at the end of the file.
    void skip_bytes(std::size_t count, std::string_view what);

  private:
    void skip_space();
    bool is_space(char c) const
    {
        return c == ' ' || c == '\t' || c == '\n' || c == '\r' || c == '\f' || c == '\v' || (m_extra && c == m_extra);
    }

    std::string m_path;
    std::string m_data;
    std::size_t m_pos = 0;
    std::int64_t m_line = 1;       ///< line at m_pos
    std::int64_t m_token_line = 1; ///< line of the last token
    char m_comment = '\0';
    char m_extra = '\0';
    bool m_swap = false;
};

} // namespace tethash::io::detail
