#pragma once
// Private to the VTK XML reader and writer: base64 and zlib blocks of binary data arrays.
#include <cstddef>
#include <string>
#include <vector>

namespace tethash::io::vtk_detail {

/// Base64 of `bytes` (with '=' padding).
std::string base64_encode(const unsigned char* bytes, std::size_t size);

/// Decodes base64 text piece by piece; whitespace is skipped and '=' padding may occur in the
/// middle (VTK encodes header and data separately), so concatenated encodings decode correctly.
class Base64Reader {
  public:
    Base64Reader(const char* begin, const char* end) : m_p(begin), m_end(end) {}
    /// Appends up to `n` decoded bytes to `out`; returns how many were appended (fewer at the end).
    std::size_t read(std::size_t n, std::vector<unsigned char>& out);
    /// Characters consumed so far from `begin`.
    const char* position() const { return m_p; }
    /// Set when a character outside the base64 alphabet was met (decoding stops there).
    bool bad() const { return m_bad; }
    char bad_char() const { return m_bad_char; }

  private:
    bool fill();
    const char* m_p;
    const char* m_end;
    unsigned char m_buf[3] = {0, 0, 0};
    int m_have = 0, m_next = 0;
    bool m_bad = false;
    char m_bad_char = 0;
};

/// Inflates one zlib block into `out` (appended); false on a corrupt block or a size mismatch.
/// `out` grows with the data actually inflated, never to `expected` before the stream yields it.
/// Throws Error(`where` ...) if tethash was built without zlib.
bool zlib_inflate(const unsigned char* src, std::size_t size, std::size_t expected, std::vector<unsigned char>& out,
                  const std::string& where);

} // namespace tethash::io::vtk_detail
