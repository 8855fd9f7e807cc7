#pragma once
/// \file study/table.hpp
/// The study's CSV: a header line and one row per measurement, written row by row and flushed so that an
/// interrupted study leaves a valid file; read back for merging shards and summarising.

#include "tethash/error.hpp"

#include <cstdio>
#include <string>
#include <vector>

namespace tethash::study {

using Row = std::vector<std::string>;

/// A CSV table held as text (the study's values are formatted once, when measured).
struct Table {
    std::vector<std::string> columns;
    std::vector<Row> rows;

    /// Column index of `name`, or -1.
    int index_of(const std::string& name) const;
    /// Reads RFC 4180 CSV (quoted fields allowed). Throws Error naming the file and line on a row whose
    /// field count differs from the header's, or when the file cannot be opened.
    static Table read_csv(const std::string& path);
    /// Writes the whole table (through io::write_atomically).
    void write_csv(const std::string& path) const;
};

/// True for columns that hold wall-clock measurements (they differ between runs of the same point):
/// names starting with "ms_" or containing "wall". Every other column is deterministic.
bool is_timing_column(const std::string& name);

/// Appends rows to a CSV file as they are measured; every row is flushed at once.
class CsvWriter {
  public:
    CsvWriter() = default;
    /// Without close(): removes the temporary file; an existing file at the path stays as it was.
    ~CsvWriter();
    CsvWriter(const CsvWriter&) = delete;
    CsvWriter& operator=(const CsvWriter&) = delete;
    /// Starts `path`: writes the header to `path`.partial (rows are flushed one by one, so a killed run
    /// leaves them there; close() renames it to `path`). Throws Error if the file cannot be created.
    void open(const std::string& path, const std::vector<std::string>& columns);
    /// Writes one row (size must equal the column count) and flushes.
    void write(const Row& row);
    /// Completes the file: renames the temporary over `path`. Throws Error if that fails.
    void close();
    /// Drops the temporary file (what the destructor does when close() was not called).
    void abandon();

  private:
    std::FILE* m_file = nullptr;
    std::string m_path;
    std::string m_tmp_path;
    std::size_t m_columns = 0;
};

/// One CSV line (no newline) with fields quoted where needed.
std::string csv_line(const Row& fields);
/// A double formatted with up to 10 significant digits ("" for NaN).
std::string fmt_double(double v);

} // namespace tethash::study
