#include "perf/bench_table.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <ctime>
#include <fstream>
#include <thread>

#include "engine/model/error.h"
#include "io/atomic_write.h"

namespace mvflow::perf {

std::string format_value(const nlohmann::ordered_json& value) {
  if (value.is_string()) return value.get<std::string>();
  if (value.is_number_integer() || value.is_number_unsigned() || value.is_boolean()) return value.dump();
  if (value.is_number_float()) {
    char text[32];
    std::snprintf(text, sizeof text, "%.4g", value.get<double>());
    return text;
  }
  return value.dump();
}

void print_table(std::ostream& out, const std::vector<Row>& rows) {
  if (rows.empty()) return;
  std::vector<std::string> columns;
  for (const auto& [key, value] : rows.front().items()) columns.push_back(key);
  std::vector<std::size_t> widths;
  for (const auto& column : columns) {
    std::size_t width = column.size();
    for (const Row& row : rows) width = std::max(width, format_value(row.value(column, Row())).size());
    widths.push_back(width);
  }
  const auto line = [&](auto cell) {
    for (std::size_t c = 0; c < columns.size(); ++c) {
      const std::string text = cell(c);
      out << (c ? "  " : "") << std::string(widths[c] - text.size(), ' ') << text;
    }
    out << '\n';
  };
  line([&](std::size_t c) { return columns[c]; });
  for (const Row& row : rows) line([&](std::size_t c) { return format_value(row.value(columns[c], Row())); });
}

void write_csv(const std::filesystem::path& path, const std::vector<Row>& rows) {
  io::write_atomically(path, false, [&](std::ostream& out) {
    if (rows.empty()) return;
    bool first = true;
    for (const auto& [key, value] : rows.front().items()) out << (first ? "" : ",") << key, first = false;
    out << '\n';
    for (const Row& row : rows) {
      first = true;
      for (const auto& [key, value] : rows.front().items()) {
        out << (first ? "" : ",") << format_value(row.value(key, Row()));
        first = false;
      }
      out << '\n';
    }
  });
}

double load_average() {
  std::ifstream file("/proc/loadavg");
  double load = -1;
  file >> load;
  return load;
}

nlohmann::ordered_json machine_description() {
  std::string model = "unknown";
  std::ifstream cpuinfo("/proc/cpuinfo");
  for (std::string line; std::getline(cpuinfo, line);)
    if (line.rfind("model name", 0) == 0) {
      model = line.substr(line.find(':') + 2);
      break;
    }
  const std::time_t now = std::chrono::system_clock::to_time_t(std::chrono::system_clock::now());
  char date[32];
  std::strftime(date, sizeof date, "%Y-%m-%d %H:%M UTC", std::gmtime(&now));
  nlohmann::ordered_json machine;
  machine["cpu"] = model;
  machine["cores"] = std::thread::hardware_concurrency();
  machine["load_average_1min"] = load_average();
  machine["date"] = date;
  return machine;
}

}  // namespace mvflow::perf
