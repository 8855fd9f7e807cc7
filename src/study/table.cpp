// CSV reading and writing for the study.
#include "tethash/study/table.hpp"

#include "tethash/error.hpp"
#include "tethash/io/mesh_io.hpp"

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>

namespace tethash::study {

int Table::index_of(const std::string& name) const
{
    for (std::size_t i = 0; i < columns.size(); ++i)
        if (columns[i] == name) return static_cast<int>(i);
    return -1;
}

namespace {

/// Splits CSV text into records; quoted fields may hold commas, quotes ("") and newlines.
std::vector<std::pair<std::size_t, Row>> parse_csv(const std::string& text)
{
    std::vector<std::pair<std::size_t, Row>> records;
    Row row;
    std::string field;
    bool quoted = false, any = false;
    std::size_t line = 1, record_line = 1;
    for (std::size_t i = 0; i < text.size(); ++i) {
        const char c = text[i];
        if (quoted) {
            if (c == '"') {
                if (i + 1 < text.size() && text[i + 1] == '"') {
                    field += '"';
                    ++i;
                } else {
                    quoted = false;
                }
            } else {
                if (c == '\n') ++line;
                field += c;
            }
            continue;
        }
        if (c == '"') {
            quoted = true;
            any = true;
        } else if (c == ',') {
            row.push_back(std::move(field));
            field.clear();
            any = true;
        } else if (c == '\n' || c == '\r') {
            if (c == '\r' && i + 1 < text.size() && text[i + 1] == '\n') ++i;
            if (any || !field.empty()) {
                row.push_back(std::move(field));
                records.emplace_back(record_line, std::move(row));
            }
            row.clear();
            field.clear();
            any = false;
            ++line;
            record_line = line;
        } else {
            field += c;
            any = true;
        }
    }
    if (any || !field.empty()) {
        row.push_back(std::move(field));
        records.emplace_back(record_line, std::move(row));
    }
    return records;
}

} // namespace

Table Table::read_csv(const std::string& path)
{
    std::ifstream in(path, std::ios::binary);
    if (!in) throw Error(path + ": cannot open CSV file");
    std::stringstream ss;
    ss << in.rdbuf();
    auto records = parse_csv(ss.str());
    if (records.empty()) throw Error(path + ":1: expected a CSV header line, found an empty file");
    Table t;
    t.columns = std::move(records.front().second);
    for (std::size_t r = 1; r < records.size(); ++r) {
        if (records[r].second.size() != t.columns.size())
            throw Error(path + ":" + std::to_string(records[r].first) + ": expected " +
                        std::to_string(t.columns.size()) + " fields, found " +
                        std::to_string(records[r].second.size()));
        t.rows.push_back(std::move(records[r].second));
    }
    return t;
}

void Table::write_csv(const std::string& path) const
{
    std::string text = csv_line(columns) + "\n";
    for (const Row& r : rows)
        text += csv_line(r) + "\n";
    io::write_text_file(path, text);
}

bool is_timing_column(const std::string& name)
{
    return name.rfind("ms_", 0) == 0 || name.find("wall") != std::string::npos;
}

std::string csv_line(const Row& fields)
{
    std::string s;
    for (std::size_t i = 0; i < fields.size(); ++i) {
        if (i) s += ',';
        const std::string& f = fields[i];
        if (f.find_first_of(",\"\n\r") == std::string::npos) {
            s += f;
        } else {
            s += '"';
            for (char c : f) {
                if (c == '"') s += '"';
                s += c;
            }
            s += '"';
        }
    }
    return s;
}

std::string fmt_double(double v)
{
    if (std::isnan(v)) return "";
    char buf[64];
    std::snprintf(buf, sizeof buf, "%.10g", v);
    return buf;
}

CsvWriter::~CsvWriter()
{
    abandon();
}

void CsvWriter::open(const std::string& path, const std::vector<std::string>& columns)
{
    abandon();
    namespace fs = std::filesystem;
    const fs::path target(path);
    const fs::path dir = target.has_parent_path() ? target.parent_path() : fs::path(".");
    std::string name = target.filename().string();
    name.append(".partial"); // visible: `tail -f study.csv.partial` follows a running study
    m_tmp_path = (dir / name).string();
    m_file = std::fopen(m_tmp_path.c_str(), "wb");
    if (!m_file) {
        m_tmp_path.clear();
        throw WriteError(path + ": cannot create file: " + std::strerror(errno));
    }
    m_path = path;
    m_columns = columns.size();
    const std::string line = csv_line(columns) + "\n";
    if (std::fwrite(line.data(), 1, line.size(), m_file) != line.size() || std::fflush(m_file) != 0) {
        abandon();
        throw WriteError(path + ": write failed: " + std::strerror(errno));
    }
}

void CsvWriter::write(const Row& row)
{
    if (!m_file) throw Error("CsvWriter: write before open");
    if (row.size() != m_columns)
        throw Error(m_path + ": row has " + std::to_string(row.size()) + " fields, header has " +
                    std::to_string(m_columns));
    const std::string line = csv_line(row) + "\n";
    if (std::fwrite(line.data(), 1, line.size(), m_file) != line.size() || std::fflush(m_file) != 0)
        throw WriteError(m_path + ": write failed: " + std::strerror(errno));
}

void CsvWriter::close()
{
    if (!m_file) return;
    const bool ok = std::fclose(m_file) == 0;
    m_file = nullptr;
    if (!ok) {
        abandon();
        throw WriteError(m_path + ": write failed: " + std::strerror(errno));
    }
    std::error_code ec;
    std::filesystem::rename(m_tmp_path, m_path, ec);
    if (ec) {
        abandon();
        throw WriteError(m_path + ": cannot move the temporary file into place: " + ec.message());
    }
    m_tmp_path.clear();
}

void CsvWriter::abandon()
{
    if (m_file) std::fclose(m_file);
    m_file = nullptr;
    if (!m_tmp_path.empty()) {
        std::error_code ec;
        std::filesystem::remove(m_tmp_path, ec);
        m_tmp_path.clear();
    }
}

} // namespace tethash::study
