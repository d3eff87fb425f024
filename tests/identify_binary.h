// Running the identify binary from the tests, as a user runs it.
#pragma once

#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

namespace mcrewave::testing {

struct RunResult {
  int exit_code = -1;
  std::string output;  // stdout and stderr together
};

// Runs `identify <arguments>` through the shell (arguments may redirect), with
// `environment` ("NAME=value ...", may be empty) set for it.
inline RunResult RunIdentify(const std::string& arguments, const std::string& environment = "") {
  const std::string command =
      environment + " " + std::string(MCREWAVE_IDENTIFY_BINARY) + " " + arguments + " 2>&1";
  RunResult result;
  FILE* pipe = popen(command.c_str(), "r");
  if (pipe == nullptr) return result;
  char buffer[4096];
  while (fgets(buffer, sizeof buffer, pipe) != nullptr) result.output += buffer;
  const int status = pclose(pipe);
  result.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return result;
}

// A path in the source tree.
inline std::string SourcePath(const std::string& relative) {
  return std::string(MCREWAVE_SOURCE_DIR) + "/" + relative;
}

// An empty directory of the test's own under the test temporary directory.
inline std::string FreshDirectory(const std::string& name) {
  const std::filesystem::path dir = std::filesystem::path(::testing::TempDir()) / name;
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir.string();
}

inline std::string ReadText(const std::string& path) {
  std::ifstream file(path, std::ios::binary);
  std::ostringstream text;
  text << file.rdbuf();
  return text.str();
}

// Whether `text` holds `part`.
inline bool Contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

// A summary.yaml without the lines that differ between two runs of one config into
// two folders: wall times, the scan's thread count and the folder.
inline std::string WithoutRunLines(const std::string& yaml) {
  std::istringstream lines(yaml);
  std::string kept;
  for (std::string line; std::getline(lines, line);) {
    if (line.find("wall_time_s:") != std::string::npos ||
        line.find("scan_threads:") != std::string::npos ||
        line.find("folder:") != std::string::npos) {
      continue;
    }
    kept += line + "\n";
  }
  return kept;
}

// The identified modulus of zone `zone` (0-based) in a run's zones.csv [Pa]:
// zone,name,start_m,end_m,nominal_modulus_pa,modulus_pa,... (app/zones_csv.h).
inline double ZoneModulus(const std::string& zones_csv, int zone) {
  std::istringstream lines(ReadText(zones_csv));
  std::string line;
  std::getline(lines, line);  // header
  for (int z = 0; z <= zone; ++z) std::getline(lines, line);
  std::istringstream cells(line);
  std::string cell;
  for (int c = 0; c < 6; ++c) std::getline(cells, cell, ',');
  return std::stod(cell);
}

}  // namespace mcrewave::testing
