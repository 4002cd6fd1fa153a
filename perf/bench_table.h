#pragma once
// mvflow_bench's output: rows of named values, printed as an aligned text table, written as CSV
// (one file per suite) and as one JSON document with the machine it ran on.

#include <nlohmann/json.hpp>

#include <filesystem>
#include <ostream>
#include <string>
#include <vector>

namespace mvflow::perf {

using Row = nlohmann::ordered_json;  //!< column name → number or string, in column order

//! The rows as a text table (columns of the first row; numbers as given by format_value).
void print_table(std::ostream& out, const std::vector<Row>& rows);
//! The rows as CSV with a header line, through a temporary file renamed into place (io/atomic_write.h).
//! \throw IoError when the file cannot be written; the old file is then untouched.
void write_csv(const std::filesystem::path& path, const std::vector<Row>& rows);
//! A value for the text table and CSV: integers as they are, other numbers with 4 significant
//! digits.
std::string format_value(const nlohmann::ordered_json& value);

//! What the numbers were measured on: the CPU model (/proc/cpuinfo), its cores, the load
//! average (/proc/loadavg) now, the date.
nlohmann::ordered_json machine_description();
//! The 1-minute load average; −1 if unknown.
double load_average();

}  // namespace mvflow::perf
