#pragma once
/// The CSV files the exchanges read back from a user's program (displacements, wire centrelines).
#include <sstream>
#include <string>
#include <vector>

namespace vessel {

/// Splits a CSV line at commas, trimming spaces, tabs and a trailing '\r' from each field.
inline std::vector<std::string> csv_fields(const std::string& line) {
  std::vector<std::string> out;
  std::stringstream s(line);
  std::string f;
  while (std::getline(s, f, ',')) {
    const auto a = f.find_first_not_of(" \t\r");
    const auto b = f.find_last_not_of(" \t\r");
    out.push_back(a == std::string::npos ? "" : f.substr(a, b - a + 1));
  }
  return out;
}

}  // namespace vessel
