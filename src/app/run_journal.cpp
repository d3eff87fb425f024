#include "app/run_journal.h"

#include <unistd.h>

#include <cerrno>
#include <cinttypes>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <utility>

#include "mcrewave/app/config.h"
#include "mcrewave/core/version.h"

namespace mcrewave::internal {
namespace {

// FNV-1a over the bytes of text, 64 bits.
std::uint64_t Fnv1a(const std::string& text) {
  std::uint64_t hash = 14695981039346656037ull;
  for (const unsigned char byte : text) {
    hash ^= byte;
    hash *= 1099511628211ull;
  }
  return hash;
}

std::string Escape(const std::string& text) {
  std::string out;
  for (const char c : text) {
    if (c == '\\') {
      out += "\\\\";
    } else if (c == '\t') {
      out += "\\t";
    } else if (c == '\n') {
      out += "\\n";
    } else if (c == '\r') {
      out += "\\r";
    } else {
      out += c;
    }
  }
  return out;
}

std::string Unescape(const std::string& text) {
  std::string out;
  for (std::size_t i = 0; i < text.size(); ++i) {
    if (text[i] != '\\' || i + 1 == text.size()) {
      out += text[i];
      continue;
    }
    const char next = text[++i];
    out += next == 't' ? '\t' : next == 'n' ? '\n' : next == 'r' ? '\r' : next;
  }
  return out;
}

}  // namespace

std::string StudyFingerprint(const Config& config, const std::string& study) {
  Config runs = config;
  const Config defaults;
  runs.study.threads = defaults.study.threads;
  runs.study.folder = defaults.study.folder;
  runs.study.figures = defaults.study.figures;
  runs.output = defaults.output;
  char hex[17];
  std::snprintf(hex, sizeof(hex), "%016" PRIx64,
                Fnv1a(std::string(kVersion) + "\n" + study + "\n" + ConfigToYaml(runs)));
  return hex;
}

std::unique_ptr<RunJournal> OpenStudyJournal(const std::string& path, const Config& config,
                                             const std::string& study) {
  if (path.empty()) return nullptr;
  return std::make_unique<RunJournal>(
      path, "mcrewave " + study + " study " + StudyFingerprint(config, study));
}

RunJournal::RunJournal(std::string path, std::string header) : path_(std::move(path)) {
  namespace fs = std::filesystem;
  std::error_code error;
  const fs::path parent = fs::path(path_).parent_path();
  if (!parent.empty()) fs::create_directories(parent, error);
  bool keep = false;
  std::uintmax_t valid_bytes = 0;  // through the last complete, readable line
  {
    std::ifstream in(path_, std::ios::binary);
    std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    std::size_t start = 0;
    bool first = true;
    // Complete lines only: a last line without its line end was cut short.
    for (std::size_t end = text.find('\n'); end != std::string::npos;
         start = end + 1, end = text.find('\n', start)) {
      const std::string line = text.substr(start, end - start);
      if (first) {
        keep = line == header;
        first = false;
        if (!keep) break;
        valid_bytes = end + 1;
        continue;
      }
      const std::size_t tab = line.find('\t');
      char* parsed_end = nullptr;
      const long index = std::strtol(line.c_str(), &parsed_end, 10);
      if (tab == std::string::npos || parsed_end != line.c_str() + tab || index < 0) break;
      restored_[static_cast<int>(index)] = line.substr(tab + 1);
      valid_bytes = end + 1;
    }
  }
  if (!keep) restored_.clear();
  // What follows the last good line (a line cut short) goes, so that the next record
  // starts a line of its own.
  if (keep) fs::resize_file(path_, valid_bytes, error);
  file_ = std::fopen(path_.c_str(), keep ? "ab" : "wb");
  if (file_ == nullptr) {
    throw std::runtime_error("cannot write the study journal " + path_ + ": " +
                             std::strerror(errno));
  }
  if (!keep) {
    std::fprintf(file_, "%s\n", header.c_str());
    std::fflush(file_);
  }
}

RunJournal::~RunJournal() {
  if (file_ != nullptr) std::fclose(file_);
}

void RunJournal::Record(int index, const std::string& record) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (file_ == nullptr) return;
  if (std::fprintf(file_, "%d\t%s\n", index, record.c_str()) < 0 || std::fflush(file_) != 0 ||
      ::fsync(::fileno(file_)) != 0) {
    throw std::runtime_error("cannot write the study journal " + path_ + ": " +
                             std::strerror(errno));
  }
}

void RunJournal::Remove() {
  std::lock_guard<std::mutex> lock(mutex_);
  if (file_ != nullptr) std::fclose(file_);
  file_ = nullptr;
  std::error_code error;
  std::filesystem::remove(path_, error);
}

void RecordWriter::Separate() {
  if (!text_.empty()) text_ += '\t';
}

RecordWriter& RecordWriter::Add(double value) {
  Separate();
  char text[64];
  // %a: the exact binary value (nan and inf as words)
  std::snprintf(text, sizeof(text), "%a", value);
  text_ += text;
  return *this;
}

RecordWriter& RecordWriter::Add(std::int64_t value) {
  Separate();
  text_ += std::to_string(value);
  return *this;
}

RecordWriter& RecordWriter::Add(const std::string& value) {
  Separate();
  // A leading '=' keeps an empty text a field of its own.
  text_ += "=" + Escape(value);
  return *this;
}

RecordWriter& RecordWriter::Add(const std::vector<double>& values) {
  Add(static_cast<std::int64_t>(values.size()));
  for (const double value : values) Add(value);
  return *this;
}

RecordReader::RecordReader(const std::string& text) {
  std::size_t start = 0;
  for (std::size_t tab = text.find('\t');; start = tab + 1, tab = text.find('\t', start)) {
    fields_.push_back(
        text.substr(start, tab == std::string::npos ? std::string::npos : tab - start));
    if (tab == std::string::npos) break;
  }
}

const std::string& RecordReader::Next() {
  if (position_ >= fields_.size()) throw std::runtime_error("the record ends early");
  return fields_[position_++];
}

double RecordReader::Double() {
  const std::string& field = Next();
  char* end = nullptr;
  const double value = std::strtod(field.c_str(), &end);
  if (field.empty() || end != field.c_str() + field.size()) {
    throw std::runtime_error("not a number: '" + field + "'");
  }
  return value;
}

std::int64_t RecordReader::Integer() {
  const std::string& field = Next();
  char* end = nullptr;
  const long long value = std::strtoll(field.c_str(), &end, 10);
  if (field.empty() || end != field.c_str() + field.size()) {
    throw std::runtime_error("not an integer: '" + field + "'");
  }
  return value;
}

std::string RecordReader::Text() {
  const std::string& field = Next();
  if (field.empty() || field[0] != '=') throw std::runtime_error("not a text: '" + field + "'");
  return Unescape(field.substr(1));
}

std::vector<double> RecordReader::Doubles() {
  const std::int64_t size = Integer();
  if (size < 0 || static_cast<std::size_t>(size) > fields_.size()) {
    throw std::runtime_error("not a list size");
  }
  std::vector<double> values;
  for (std::int64_t i = 0; i < size; ++i) values.push_back(Double());
  return values;
}

}  // namespace mcrewave::internal
