#pragma once
// Reads a `refine --dump-fields` PLY back for the tests, with its own parser of the header's
// declarations (not io/'s), so that a test compares the writer with an independent reading.

#include <gtest/gtest.h>

#include <array>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "test_support.h"

namespace mvflow::test {

struct VertexFieldsDump {
  std::map<std::string, std::string> comments;       //!< "iteration" → "7", "time_step" → "0.06…"
  std::vector<std::string> doubles;                  //!< the double properties' names, in order
  std::vector<std::string> bytes;                    //!< the uchar properties' names, in order
  std::vector<std::vector<double>> rows;             //!< per vertex, the doubles
  std::vector<std::vector<std::uint8_t>> byte_rows;  //!< per vertex, the uchars
  std::vector<std::array<std::int32_t, 3>> faces;

  double value(std::size_t vertex, const std::string& name) const {
    for (std::size_t i = 0; i < doubles.size(); ++i)
      if (doubles[i] == name) return rows[vertex][i];
    ADD_FAILURE() << "no property " << name;
    return 0.0;
  }
  std::uint8_t byte(std::size_t vertex, const std::string& name) const {
    for (std::size_t i = 0; i < bytes.size(); ++i)
      if (bytes[i] == name) return byte_rows[vertex][i];
    ADD_FAILURE() << "no property " << name;
    return 0;
  }
};

// Assumes this host is little-endian (x86-64, arm64), as the file is.
inline VertexFieldsDump read_vertex_fields_dump(const std::filesystem::path& file) {
  const std::string data = read_text(file);
  VertexFieldsDump dump;
  const std::size_t header_end = data.find("end_header\n");
  EXPECT_NE(header_end, std::string::npos) << file;
  std::istringstream header(data.substr(0, header_end));
  std::string line;
  std::size_t vertices = 0, faces = 0;
  bool in_faces = false;
  while (std::getline(header, line)) {
    std::istringstream words(line);
    std::string first, second, third;
    words >> first >> second >> third;
    if (first == "comment" && !third.empty()) dump.comments[second] = third;
    if (first == "element") {
      in_faces = second == "face";
      (in_faces ? faces : vertices) = std::stoul(third);
    }
    if (first == "property" && !in_faces) (second == "double" ? dump.doubles : dump.bytes).push_back(third);
  }
  const char* at = data.data() + header_end + std::strlen("end_header\n");
  for (std::size_t v = 0; v < vertices; ++v) {
    std::vector<double> row(dump.doubles.size());
    std::memcpy(row.data(), at, 8 * row.size());
    at += 8 * row.size();
    dump.rows.push_back(row);
    dump.byte_rows.emplace_back(at, at + dump.bytes.size());
    at += dump.bytes.size();
  }
  for (std::size_t f = 0; f < faces; ++f) {
    EXPECT_EQ(*at, 3) << "face " << f;
    std::array<std::int32_t, 3> corners{};
    std::memcpy(corners.data(), at + 1, 12);
    at += 13;
    dump.faces.push_back(corners);
  }
  EXPECT_EQ(at, data.data() + data.size()) << file << ": bytes after the faces";
  return dump;
}

}  // namespace mvflow::test
