#pragma once
// The study's outputs (private): the output folder, study.json (machine, scenes, notes, summary) and the merge
// of shards (merge_studies in study.hpp). The rows themselves are written by CsvWriter (table.hpp).
#include "plan.hpp"

#include "tethash/study/json.hpp"

#include <string>

namespace tethash::study {

/// Checks, without creating anything, that the folder `dir` exists or can be made and accepts files.
void check_out_dir(const std::string& dir);
/// Makes the output folder (and its parents).
void make_out_dir(const std::string& dir);

/// Machine description: {"cores", "cpu", "host", "openmp_max_threads", "compiler", "flags", "date"}.
void write_machine(JsonWriter& j, const std::string& compiler_flags);
/// The members "command" and "machine" (write_machine) that a run's JSON document (study.json, spheres.json)
/// records after its format's name.
void write_run_members(JsonWriter& j, const std::string& command_line, const std::string& compiler_flags);
/// The document of `j` and a newline as the file `path`.
void write_json_file(const std::string& path, const JsonWriter& j);
/// Median / min / max per point of every timing column (the other columns: the first repeat's value).
void write_summary(JsonWriter& j, const Table& table);
/// DIR/study.json of a finished (or interrupted) run that measured `table` in `seconds`.
void write_study_json(const StudyPlan& plan, const StudyResult& result, const Table& table, double seconds);

} // namespace tethash::study
