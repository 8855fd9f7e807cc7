// Base64 and zlib blocks of VTK XML data arrays (see vtk_encoding.hpp).
#include "vtk_encoding.hpp"

#include "tethash/error.hpp"

#include <algorithm>
#include <limits>

#ifdef TETHASH_HAVE_ZLIB
#include <zlib.h>
#endif

namespace tethash::io::vtk_detail {

namespace {
const char* const k_b64 = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
int b64_value(unsigned char c)
{
    if (c >= 'A' && c <= 'Z') return c - 'A';
    if (c >= 'a' && c <= 'z') return c - 'a' + 26;
    if (c >= '0' && c <= '9') return c - '0' + 52;
    if (c == '+') return 62;
    if (c == '/') return 63;
    return -1;
}
} // namespace

std::string base64_encode(const unsigned char* b, std::size_t size)
{
    std::string out;
    out.reserve((size + 2) / 3 * 4);
    std::size_t i = 0;
    for (; i + 3 <= size; i += 3) {
        const unsigned v = (unsigned(b[i]) << 16) | (unsigned(b[i + 1]) << 8) | b[i + 2];
        out += k_b64[(v >> 18) & 63];
        out += k_b64[(v >> 12) & 63];
        out += k_b64[(v >> 6) & 63];
        out += k_b64[v & 63];
    }
    if (i < size) {
        const unsigned v = (unsigned(b[i]) << 16) | (i + 1 < size ? unsigned(b[i + 1]) << 8 : 0u);
        out += k_b64[(v >> 18) & 63];
        out += k_b64[(v >> 12) & 63];
        out += i + 1 < size ? k_b64[(v >> 6) & 63] : '=';
        out += '=';
    }
    return out;
}

bool Base64Reader::fill()
{
    // Reads one quantum of 4 characters (skipping whitespace); '=' ends it early.
    int vals[4];
    int got = 0;
    while (got < 4 && m_p < m_end) {
        const unsigned char c = static_cast<unsigned char>(*m_p);
        if (c == ' ' || c == '\n' || c == '\r' || c == '\t') {
            ++m_p;
            continue;
        }
        if (c == '=') {
            ++m_p;
            if (got == 0) continue; // stray padding between pieces
            // Consume the rest of the padding of this quantum.
            int pads = 1;
            while (got + pads < 4 && m_p < m_end && *m_p == '=')
                ++m_p, ++pads;
            break;
        }
        const int v = b64_value(c);
        if (v < 0) {
            m_bad = true;
            m_bad_char = static_cast<char>(c);
            m_end = m_p;
            break;
        }
        vals[got++] = v;
        ++m_p;
    }
    if (got < 2) return false;
    for (int i = got; i < 4; ++i)
        vals[i] = 0;
    const unsigned v =
        (unsigned(vals[0]) << 18) | (unsigned(vals[1]) << 12) | (unsigned(vals[2]) << 6) | unsigned(vals[3]);
    m_buf[0] = static_cast<unsigned char>(v >> 16);
    m_buf[1] = static_cast<unsigned char>(v >> 8);
    m_buf[2] = static_cast<unsigned char>(v);
    m_have = got - 1;
    m_next = 0;
    return true;
}

std::size_t Base64Reader::read(std::size_t n, std::vector<unsigned char>& out)
{
    std::size_t done = 0;
    while (done < n) {
        if (m_next >= m_have && !fill()) break;
        while (m_next < m_have && done < n) {
            out.push_back(m_buf[m_next++]);
            ++done;
        }
    }
    return done;
}

bool zlib_inflate(const unsigned char* src, std::size_t size, std::size_t expected, std::vector<unsigned char>& out,
                  const std::string& where)
{
#ifdef TETHASH_HAVE_ZLIB
    (void)where;
    // The output grows with what the stream actually yields (never to the declared size up front),
    // so that a header declaring gigabytes costs only what its data inflate to.
    const std::size_t start = out.size();
    z_stream zs{};
    if (inflateInit(&zs) != Z_OK) return false;
    zs.next_in = const_cast<Bytef*>(src);
    zs.avail_in = static_cast<uInt>(std::min<std::size_t>(size, std::numeric_limits<uInt>::max()));
    std::size_t produced = 0;
    bool ok = false;
    for (;;) {
        if (zs.avail_in == 0 && size > 0) { // feed the rest of a block larger than 4 GiB
            const std::size_t used = static_cast<std::size_t>(zs.next_in - src);
            zs.avail_in = static_cast<uInt>(std::min<std::size_t>(size - used, std::numeric_limits<uInt>::max()));
        }
        if (produced == expected) {
            // All expected bytes are there: the stream must end without yielding another byte.
            unsigned char extra = 0;
            int rc = Z_OK;
            do {
                zs.next_out = &extra;
                zs.avail_out = 1;
                rc = inflate(&zs, Z_NO_FLUSH);
            } while (rc == Z_OK && zs.avail_out == 1);
            ok = rc == Z_STREAM_END && zs.avail_out == 1;
            break;
        }
        const std::size_t grow = std::min(
            {expected - produced, std::max<std::size_t>(std::size_t(1) << 16, produced), std::size_t(1) << 30});
        out.resize(start + produced + grow);
        zs.next_out = out.data() + start + produced;
        zs.avail_out = static_cast<uInt>(grow);
        const int rc = inflate(&zs, Z_NO_FLUSH);
        produced += grow - zs.avail_out;
        if (rc == Z_STREAM_END) {
            ok = produced == expected;
            break;
        }
        if (rc != Z_OK) break; // corrupt, or the input ended before the stream did
    }
    inflateEnd(&zs);
    out.resize(ok ? start + expected : start);
    return ok;
#else
    (void)src, (void)size, (void)expected, (void)out;
    throw Error(where + ": zlib-compressed data (vtkZLibDataCompressor), but tethash was built without zlib");
#endif
}

} // namespace tethash::io::vtk_detail
