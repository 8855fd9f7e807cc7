// The detector's statistics as one table (stats_table.hpp).
#include "tethash/study/stats_table.hpp"

#include "tethash/study/table.hpp"

namespace tethash::study {

std::string stat_text(const StatField& field, const DetectStats& stats)
{
    const double v = field.get(stats);
    if (field.kind == StatKind::count) return std::to_string(static_cast<long long>(v));
    return fmt_double(v);
}

void write_stat(JsonWriter& j, const StatField& field, const DetectStats& stats)
{
    const double v = field.get(stats);
    j.key(field.name);
    if (field.kind == StatKind::count)
        j.value(static_cast<long long>(v));
    else
        j.value(v);
}

} // namespace tethash::study
