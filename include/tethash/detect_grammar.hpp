#pragma once
/// \file detect_grammar.hpp
/// The text grammar of the detector's parameters: one parser behind every command's options, the scene file's
/// `[detector]` table, the study's value lists and the Python module, so that a value means the same thing
/// everywhere (docs/detection.md, "One grammar for every command"). Lengths are plain numbers; factors are written
/// with a leading x ("x0.5"). Every function throws Error naming `option` and the text. An FEM code that sets
/// DetectParams in code needs none of it (detect.hpp).

#include "tethash/detect.hpp"
#include "tethash/error.hpp"

#include <cstdint>
#include <string>

namespace tethash {

/// Most threads any command accepts: 256, or the hardware threads if there are more. Beyond it the OpenMP
/// runtime fails (or crashes) while starting the team, so it is refused before.
int max_threads();
/// "N": 0 = every hardware thread (OpenMP's default, OMP_NUM_THREADS where set), 1..max_threads().
int parse_threads(const std::string& text, const std::string& option = "--threads");
/// Checks a thread count given as a number (0 = all, 1..max_threads()); returns it.
int check_threads(long long threads, const std::string& option = "--threads");
/// "auto" (the mean edge length) | "L" (a length > 0) | "xF" (F > 0 times the mean edge length):
/// sets params.cell_size_mode and params.cell_size.
void parse_cell_size(const std::string& text, DetectParams& params, const std::string& option = "--cell-size");
/// "auto" (0: the detector chooses) | "N" (N ≥ 1 buckets) | "xF" (F > 0 times `vertices`, rounded up to a power
/// of two). Returns the table size for DetectParams::table_size. `vertices` 0: checks the syntax only.
std::int64_t parse_table_size(const std::string& text, std::int64_t vertices,
                              const std::string& option = "--table-size");
/// "L" (a length ≥ 0; 0 = no candidate reuse) | "xF" (F ≥ 0 times the cell size): sets skin_mode and skin.
void parse_skin(const std::string& text, DetectParams& params, const std::string& option = "--skin");
/// The numbers of these grammars, also read by the study's value lists: a whole-string finite decimal number, a
/// whole-string integer. Throw Error "OPTION: expected a number (an integer), found 'TEXT'".
double parse_number(const std::string& text, const std::string& option);
long long parse_integer(const std::string& text, const std::string& option);
/// "teschner" / "column"; throws Error for anything else.
HashFunction parse_hash_function(const std::string& name);
/// The names of detect.hpp's to_string(Method); throws Error naming `option`, the text and the list.
Method parse_method(const std::string& text, const std::string& option = "--method");

} // namespace tethash
