// The names of an enum's values in one table that both directions read: value -> name for output, name -> value
// for parsing. Private to the libraries (core, io, sim and study include it as "core/enum_names.hpp").
#pragma once

#include <cstddef>
#include <optional>
#include <string_view>

namespace tethash::detail {

/// One name of one value. A value may stand in several rows (aliases): its first row gives its name.
template <class Enum> struct EnumName {
    Enum value;
    const char* name;
};

/// The name of `value`: its first row in `table`, or `otherwise` when no row names it.
template <class Enum, std::size_t N>
constexpr const char* name_of(const EnumName<Enum> (&table)[N], Enum value, const char* otherwise = "?")
{
    for (const auto& row : table)
        if (row.value == value) return row.name;
    return otherwise;
}

/// The value `name` stands for in `table` (any of its rows), or nothing when no row has that name.
template <class Enum, std::size_t N>
constexpr std::optional<Enum> value_named(const EnumName<Enum> (&table)[N], std::string_view name)
{
    for (const auto& row : table)
        if (name == row.name) return row.value;
    return std::nullopt;
}

} // namespace tethash::detail
