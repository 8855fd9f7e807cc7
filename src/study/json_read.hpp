#pragma once
// Reading JSON back: what the study needs to merge shards (a shard's study.json: its sweep and point count),
// without matching text patterns. A complete reader of RFC 8259 documents into a small tree.
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace tethash::study {

struct JsonMember;

struct JsonValue {
    enum Kind { null, boolean, number, string, array, object };
    Kind kind = null;
    bool flag = false;               ///< boolean
    double num = 0;                  ///< number
    std::string text;                ///< string (unescaped); number: its text as written
    std::vector<JsonValue> items;    ///< array
    std::vector<JsonMember> members; ///< object, in document order

    /// The member `name` of an object (the last one if repeated), or nullptr.
    const JsonValue* find(std::string_view name) const;
};

/// One member of an object. (Not a std::pair: a pair of an incomplete type is refused by clang's library checks.)
struct JsonMember {
    std::string name;
    JsonValue value;
};

/// Parses one JSON document (surrounding white space allowed). Throws Error "`what`: invalid JSON at line L: ...".
JsonValue parse_json(std::string_view text, const std::string& what);

} // namespace tethash::study
