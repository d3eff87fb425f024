// Internal: the finished runs of a study on disk, so that a study killed part way
// (SIGKILL, power loss) resumes from them when started again with the same config, and
// its final files are the same bits as an uninterrupted run's (docs/robustness.md,
// "Resuming a study").
//
// The journal is one text file: a first line naming the study and the fingerprint of
// everything its runs depend on (the mcrewave version and the config, the keys that do
// not change a run's numbers left out); then one line per finished run, "<index>\t<record>",
// appended, flushed and synced to disk as the run ends. A record is a tab-separated list
// of fields written by RecordWriter: numbers as C99 hexadecimal floats (exact), text
// with its backslashes, tabs and line ends escaped. A line cut short by a power loss has
// no line end and is ignored (its run is run again), as is every line after it.
#pragma once

#include <cstdint>
#include <cstdio>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

namespace mcrewave {
struct Config;
}

namespace mcrewave::internal {

// The fingerprint of what a study's runs depend on: the version, the study's name and
// the config as YAML without study.threads, study.folder, study.figures and
// output.* (FNV-1a, 64 bits, as 16 hex digits).
std::string StudyFingerprint(const Config& config, const std::string& study);

class RunJournal;

// The journal of `study` at path, its header naming the study and its fingerprint; null
// when path is empty (no journal).
std::unique_ptr<RunJournal> OpenStudyJournal(const std::string& path, const Config& config,
                                             const std::string& study);

class RunJournal {
 public:
  // Opens path (creating its folder), keeping the records of a journal whose first line
  // is `header` and starting afresh (truncating) when there is none or another header.
  // Throws std::runtime_error naming path when it cannot be read or written.
  RunJournal(std::string path, std::string header);
  ~RunJournal();
  RunJournal(const RunJournal&) = delete;
  RunJournal& operator=(const RunJournal&) = delete;

  // The records of the runs finished before, by index.
  const std::map<int, std::string>& restored() const { return restored_; }
  // Appends run `index`'s record (no line end inside: RecordWriter escapes them),
  // flushed and synced. Thread-safe. Throws std::runtime_error naming the file.
  void Record(int index, const std::string& record);
  // Closes and deletes the file: the study's results are written.
  void Remove();
  const std::string& path() const { return path_; }

 private:
  std::string path_;
  std::map<int, std::string> restored_;
  std::FILE* file_ = nullptr;
  std::mutex mutex_;
};

// The fields of one record.
class RecordWriter {
 public:
  RecordWriter& Add(double value);
  RecordWriter& Add(std::int64_t value);
  RecordWriter& Add(int value) { return Add(static_cast<std::int64_t>(value)); }
  RecordWriter& Add(std::uint64_t value) { return Add(static_cast<std::int64_t>(value)); }
  RecordWriter& Add(bool value) { return Add(static_cast<std::int64_t>(value ? 1 : 0)); }
  RecordWriter& Add(const std::string& value);
  RecordWriter& Add(const std::vector<double>& values);  // its size, then each value
  const std::string& text() const { return text_; }

 private:
  void Separate();
  std::string text_;
};

// Reads the fields back in the order written; every getter throws std::runtime_error
// when the record ends early or a field does not parse (the run is then run again).
class RecordReader {
 public:
  explicit RecordReader(const std::string& text);
  double Double();
  std::int64_t Integer();
  bool Bool() { return Integer() != 0; }
  std::string Text();
  std::vector<double> Doubles();
  // True when every field was read.
  bool AtEnd() const { return position_ >= fields_.size(); }

 private:
  const std::string& Next();
  std::vector<std::string> fields_;
  std::size_t position_ = 0;
};

}  // namespace mcrewave::internal
