// Internal: the pieces every study shares (study.cpp, damage_study.cpp): the thread
// pool that stores runs by index, progress lines, number formats and the writer of a
// study folder.
#pragma once

#include <chrono>
#include <functional>
#include <mutex>
#include <string>
#include <utility>
#include <vector>

#include "mcrewave/app/matrix_identification_run.h"

namespace mcrewave {
struct Config;
}

namespace mcrewave::internal {

using Clock = std::chrono::steady_clock;

double SecondsSince(Clock::time_point start);
// threads, or every core when 0.
int ResolveThreads(int threads);
// "1 min 05 s" or "42 s".
std::string Duration(double seconds);

// Counts completed runs and logs one progress line per run with the time left,
// extrapolated from the mean time per completed run so far.
class Progress {
 public:
  Progress(std::string what, int total) : what_(std::move(what)), total_(total) {}
  // `runs` of the total were restored from a journal: the lines count the others.
  void Restored(int runs);
  void RunDone();

 private:
  std::string what_;
  int total_;
  int done_ = 0;
  std::mutex mutex_;
  Clock::time_point start_ = Clock::now();
};

// Calls task(i) for every i in [0, count) on `threads` threads, each taking the next
// index not yet taken, and progress->RunDone() after each. The tasks must write only
// their own results (by index). The first exception a task throws is rethrown once
// every thread has stopped (the others stop taking new indices).
void ParallelFor(int count, int threads, const std::function<void(int)>& task, Progress* progress);

class RunJournal;

// A matrix model's study truth: the model of model.manifest, its noise-free
// measurements (the truth of data: at data.truth_moduli, data.snr ignored: each run adds
// its own noise), and each zone's name and truth modulus E_ref [Pa]. Throws InputError
// naming the config, the study and the truth when the truth lacks one of the zones.
struct MatrixStudyTruth {
  MatrixStudyTruth(const Config& config, const std::string& study);
  MatrixModelData model;
  MatrixMeasurements measurements;
  std::vector<std::string> zone_names;
  std::vector<double> reference_moduli;
};

// ParallelFor over the runs a journal does not hold (null: every run): task(i), then
// journal->Record(i, encode(i)); each run the journal holds is decode(i, record)
// instead, and run again when its record does not decode (decode throws). Progress
// counts every run.
void ResumableParallelFor(int count, int threads, const std::function<void(int)>& task,
                          Progress* progress, RunJournal* journal,
                          const std::function<std::string(int)>& encode,
                          const std::function<void(int, const std::string&)>& decode);

// Number as CSV text: 10 significant digits, "nan", "inf".
std::string Csv(double value);
// Number for tables: `digits` significant digits.
std::string Brief(double value, int digits = 4);
// "zone0 210 GPa, zone1 190 GPa": each name with its modulus [Pa] in GPa, 6 digits.
std::string NamedModuliInGpa(const std::vector<std::string>& names,
                             const std::vector<double>& moduli);
// A ratio as a signed percentage with 3 decimals ("+0.012 %").
std::string Percent(double ratio);
std::string SnrText(double snr);
// Gnuplot colours of the curves, by index.
std::string Colour(int index);

// Writes `files` (name, content) into folder, then draws `figures` (name, script)
// when asked, then summary.md; returns the paths written.
std::vector<std::string> WriteStudyFolder(
    const std::string& folder, const std::vector<std::pair<std::string, std::string>>& files,
    const std::vector<std::pair<std::string, std::string>>& figures, bool draw,
    const std::string& summary);

}  // namespace mcrewave::internal
