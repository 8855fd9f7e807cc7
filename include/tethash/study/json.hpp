#pragma once
/// \file study/json.hpp
/// The one JSON writer of the project (study.json, `tethash detect --stats`, `tethash info --json`): strings
/// escaped, numbers that read back to the same double, nesting checked. Non-finite numbers are written as null
/// (JSON has no NaN or infinity); a reader sees "not measured", never an invalid file.

#include "tethash/error.hpp"

#include <cstdint>
#include <string>
#include <string_view>
#include <type_traits>
#include <vector>

namespace tethash::study {

/// `s` as a JSON string literal: quotes, backslashes and control characters escaped (\n, \t, \r, \b, \f or
/// \u00XX); other bytes (UTF-8 included) unchanged.
std::string json_quote(std::string_view s);
/// The shortest text that reads back as `v` ("0.1", "1e-300", "3"); "null" for NaN and ±infinity.
std::string json_number(double v);
/// True when `text` is a number in JSON's grammar ("-1.5e3" yes; "+1", ".5", "1.", "nan", "0x1" no).
bool is_json_number(std::string_view text);

/// Builds a JSON document. A container is laid out either as a block (one member per line, indented two spaces
/// per level) or inline (on one line, members separated by ", "); containers inside an inline one are inline.
///
///     JsonWriter j;
///     j.begin_object().key("points").value(12).key("shard").begin_object(JsonWriter::inline_layout)
///      .key("index").value(0).end_object().end_object();
///     j.str() == "{\n  \"points\": 12,\n  \"shard\": {\"index\": 0}\n}"
///
/// Misuse (a value where a key is due, closing the wrong container, str() with a container open) throws
/// std::logic_error: it is a bug of the caller, never of the input.
class JsonWriter {
  public:
    enum Layout { block_layout, inline_layout };

    JsonWriter& begin_object(Layout layout = block_layout);
    JsonWriter& end_object();
    JsonWriter& begin_array(Layout layout = inline_layout);
    JsonWriter& end_array();
    /// The next member's name (inside an object only).
    JsonWriter& key(std::string_view name);

    JsonWriter& value(std::string_view s);
    JsonWriter& value(const std::string& s) { return value(std::string_view(s)); }
    JsonWriter& value(const char* s) { return value(std::string_view(s)); }
    JsonWriter& value(double v);
    JsonWriter& value(bool v);
    template <class T, std::enable_if_t<std::is_integral_v<T> && !std::is_same_v<T, bool>, int> = 0>
    JsonWriter& value(T v)
    {
        return raw(std::to_string(v));
    }
    JsonWriter& null();
    /// A number already formatted (e.g. a CSV field): written as it is when is_json_number(text), as a string
    /// otherwise, null when empty.
    JsonWriter& number_text(std::string_view text);
    /// A complete JSON value written verbatim (another document, already checked by the caller).
    JsonWriter& raw(std::string_view json);

    /// key(name).value(v) in one call.
    template <class T> JsonWriter& member(std::string_view name, const T& v) { return key(name).value(v); }

    /// The document; throws std::logic_error while a container is open.
    const std::string& str() const;

  private:
    struct Level {
        bool object = false;
        bool block = false;
        int members = 0;
    };
    void before_value();
    void newline(std::size_t depth);
    void open(bool object, Layout layout);
    void close(bool object);

    std::string m_out;
    std::vector<Level> m_levels;
    bool m_after_key = false;
    bool m_done = false;
};

} // namespace tethash::study
