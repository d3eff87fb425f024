// End-to-end tests of `identify study`: the binary run as a user runs it on a
// tiny config (every study, 2 SNRs, 2 seeds), and on bad `study:` values.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include "identify_binary.h"

namespace mcrewave {
namespace {

using testing::FreshDirectory;
using testing::ReadText;
using testing::RunIdentify;
using testing::RunResult;

namespace fs = std::filesystem;

// The paper's bar on 12 elements, 150 steps; every study at 2 SNRs, 2 seeds.
constexpr const char* kTinyStudyConfig = R"(model: {elements: 12}
time: {window: 0.45e-3, step: 3e-6}
outer: {scan_points: 15, relative_tolerance: 1e-6}
study:
  threads: 2
  robustness:
    snr: [.inf, 10]
    seeds: 2
  relaxation:
    snr: [.inf, 10]
    moduli: [1]
    omega_min: 0.05
    omega_max: 0.4
    omega_points: 4
  cost_curves:
    snr: [.inf, 10]
    seeds: 2
    points: 11
    low: 0.9
    high: 1.1
)";

std::string WriteConfig(const std::string& directory, const std::string& text) {
  const std::string path = directory + "/study.yaml";
  std::ofstream(path) << text;
  return path;
}

TEST(IdentifyStudyTest, EveryStudyWritesItsFilesFiguresAndTheReadme) {
  const std::string directory = FreshDirectory("identify_study_all");
  const std::string config = WriteConfig(directory, kTinyStudyConfig);
  const std::string folder = directory + "/results";
  const RunResult result = RunIdentify("study " + config + " --output " + folder);
  ASSERT_EQ(result.exit_code, 0) << result.output;
  // Progress lines with the time left; the identifications' own lines hidden.
  EXPECT_NE(result.output.find("robustness: 3 / 3 runs"), std::string::npos) << result.output;
  EXPECT_NE(result.output.find("left"), std::string::npos) << result.output;
  EXPECT_EQ(result.output.find("evaluation 1:"), std::string::npos) << result.output;

  for (const char* file :
       {"robustness/runs.csv", "robustness/statistics.csv", "robustness/summary.md",
        "relaxation/cases.csv", "relaxation/sweeps.csv", "relaxation/residuals.csv",
        "relaxation/summary.md", "cost_curves/curves.csv", "cost_curves/minima.csv",
        "cost_curves/summary.md", "README.md"}) {
    EXPECT_TRUE(fs::exists(folder + "/" + file)) << file;
  }
  if (result.output.find("gnuplot not found") == std::string::npos) {
    for (const char* figure : {"robustness/robustness.png", "relaxation/sweeps_vs_omega.png",
                               "relaxation/residuals.png", "cost_curves/cost_curves.png"}) {
      ASSERT_TRUE(fs::exists(folder + "/" + figure)) << figure;
      EXPECT_GT(fs::file_size(folder + "/" + figure), 10000u) << figure;
    }
  }
  const std::string readme = ReadText(folder + "/README.md");
  for (const char* section : {"## Robustness", "## Relaxation coefficient", "## Cost curves"}) {
    EXPECT_NE(readme.find(section), std::string::npos) << section;
  }
  EXPECT_NE(readme.find("| inf | 1 | 100 % |"), std::string::npos) << readme;
  for (const auto& entry : fs::recursive_directory_iterator(folder)) {
    EXPECT_EQ(entry.path().filename().string().find(".tmp"), std::string::npos) << entry.path();
  }
}

TEST(IdentifyStudyTest, OneKindRunsThatStudyOnly) {
  const std::string directory = FreshDirectory("identify_study_one");
  const std::string config = WriteConfig(directory, kTinyStudyConfig);
  const std::string folder = directory + "/results";
  const RunResult result = RunIdentify("study " + config + " --set study.kind=cost_curves " +
                                       "--set study.figures=false -q --output " + folder);
  ASSERT_EQ(result.exit_code, 0) << result.output;
  EXPECT_EQ(result.output, "");
  EXPECT_TRUE(fs::exists(folder + "/cost_curves/minima.csv"));
  EXPECT_FALSE(fs::exists(folder + "/cost_curves/cost_curves.png"));
  EXPECT_FALSE(fs::exists(folder + "/robustness"));
  EXPECT_FALSE(fs::exists(folder + "/relaxation"));
}

// study.kind readme runs no study: it gathers README.md again from the folders
// there, the one the cost-curve study wrote among them.
TEST(IdentifyStudyTest, TheReadmeKindGathersTheSummariesAndRunsNothing) {
  const std::string directory = FreshDirectory("identify_study_readme");
  const std::string config = WriteConfig(directory, kTinyStudyConfig);
  const std::string folder = directory + "/results";
  ASSERT_EQ(RunIdentify("study " + config + " --set study.kind=cost_curves " +
                        "--set study.figures=false -q --output " + folder)
                .exit_code,
            0);
  fs::remove(folder + "/README.md");
  const RunResult result =
      RunIdentify("study " + config + " --set study.kind=readme -q --output " + folder);
  ASSERT_EQ(result.exit_code, 0) << result.output;
  std::ifstream readme(folder + "/README.md");
  std::ostringstream text;
  text << readme.rdbuf();
  EXPECT_NE(text.str().find("## Cost curves (`cost_curves/`)"), std::string::npos) << text.str();
  EXPECT_FALSE(fs::exists(folder + "/robustness"));
  EXPECT_FALSE(fs::exists(folder + "/relaxation"));
}

// The text of a study's file without the lines that give its wall time and
// thread count ("... in 0 s on 4 threads.").
std::string WithoutTimingLines(const std::string& text) {
  std::istringstream lines(text);
  std::string kept;
  for (std::string line; std::getline(lines, line);) {
    if (line.find(" threads.") == std::string::npos) kept += line + "\n";
  }
  return kept;
}

TEST(IdentifyStudyTest, EveryStudyWritesTheSameBitsOnOneTwoOrFourThreads) {
  const std::string directory = FreshDirectory("identify_study_threads");
  const std::string config = WriteConfig(directory, kTinyStudyConfig);
  std::vector<std::string> folders;
  for (const int threads : {1, 2, 4}) {
    folders.push_back(directory + "/results_" + std::to_string(threads));
    const RunResult result =
        RunIdentify("study " + config + " --set study.figures=false -q --set study.threads=" +
                    std::to_string(threads) + " --output " + folders.back());
    ASSERT_EQ(result.exit_code, 0) << result.output;
  }
  int files = 0;
  for (const auto& entry : fs::recursive_directory_iterator(folders[0])) {
    if (!entry.is_regular_file()) continue;
    const std::string relative = fs::relative(entry.path(), folders[0]).string();
    const std::string one = WithoutTimingLines(ReadText(entry.path().string()));
    for (std::size_t k = 1; k < folders.size(); ++k) {
      EXPECT_EQ(one, WithoutTimingLines(ReadText(folders[k] + "/" + relative)))
          << relative << " differs between 1 and " << (k == 1 ? 2 : 4) << " threads";
    }
    ++files;
  }
  // runs, statistics, cases, sweeps, residuals, curves, minima, 3 summaries, README.
  EXPECT_EQ(files, 11);
}

// The CSV text without its columns whose name holds "time" (wall times).
std::string WithoutTimeColumns(const std::string& csv) {
  std::istringstream lines(csv);
  std::vector<bool> keep;  // from the header
  std::string kept;
  for (std::string line; std::getline(lines, line);) {
    std::istringstream cells(line);
    std::size_t column = 0;
    for (std::string cell; std::getline(cells, cell, ','); ++column) {
      if (column == keep.size()) keep.push_back(cell.find("time") == std::string::npos);
      if (keep[column]) kept += cell + ",";
    }
    kept += "\n";
  }
  return kept;
}

// A study's summary.md without what depends on the machine: the thread count and the
// durations of its text, and the table columns whose header names a time.
std::string WithoutTimes(const std::string& markdown) {
  static const std::regex threads(" on [0-9]+ threads in ");
  static const std::regex duration("[0-9]+ min [0-9]+ s|\\b[0-9]+ s\\b");
  std::istringstream lines(markdown);
  std::vector<bool> keep;  // of the current table, from its header
  std::string kept;
  for (std::string line; std::getline(lines, line);) {
    if (line.rfind("|", 0) != 0) {
      keep.clear();
      kept += std::regex_replace(std::regex_replace(line, threads, " on T threads in "),
                                 duration, "D") +
              "\n";
      continue;
    }
    std::istringstream cells(line.substr(1));
    const bool header = keep.empty();
    std::size_t column = 0;
    for (std::string cell; std::getline(cells, cell, '|'); ++column) {
      if (header) keep.push_back(cell.find("time") == std::string::npos);
      if (column >= keep.size() || keep[column]) kept += cell + "|";
    }
    kept += "\n";
  }
  return kept;
}

TEST(IdentifyStudyTest, DamageAndComparatorStudiesWriteTheSameBitsOnOneTwoOrFourThreads) {
  // Small grids (the damage study on 10 elements at SNR inf, 12 runs; the comparator
  // at SNR 20, one seed, two model errors, 8 identifications): every CSV file and
  // summary the same on 1, 2 and 4 threads, wall times and thread counts apart.
  const std::string directory = FreshDirectory("identify_study_threads_damage_comparator");
  const std::string quick = testing::SourcePath("configs/quick.yaml");
  const std::vector<std::pair<std::string, std::string>> studies = {
      {"damage",
       " --set study.kind=damage --set study.damage.snr=[.inf] --set study.damage.seeds=1"
       " --set model.elements=10"},
      {"comparator",
       " --set study.kind=comparator --set study.comparator.snr=[20]"
       " --set study.comparator.seeds=1 --set study.comparator.errors=[none,soft_zone]"}};
  for (const auto& [study, settings] : studies) {
    std::vector<std::string> folders;
    for (const int threads : {1, 2, 4}) {
      folders.push_back(directory + "/" + study + "_" + std::to_string(threads));
      const RunResult result =
          RunIdentify("study " + quick + settings + " --set study.figures=false -q" +
                      " --set study.threads=" + std::to_string(threads) + " -o " + folders.back());
      ASSERT_EQ(result.exit_code, 0) << study << ": " << result.output;
    }
    int files = 0, summaries = 0;
    for (const auto& entry : fs::recursive_directory_iterator(folders[0])) {
      const std::string extension = entry.path().extension().string();
      if (!entry.is_regular_file() || (extension != ".csv" && extension != ".md")) continue;
      const std::string relative = fs::relative(entry.path(), folders[0]).string();
      auto comparable = [&extension](const std::string& text) {
        return extension == ".csv" ? WithoutTimeColumns(text) : WithoutTimes(text);
      };
      const std::string one = comparable(ReadText(entry.path().string()));
      for (std::size_t k = 1; k < folders.size(); ++k) {
        EXPECT_EQ(one, comparable(ReadText(folders[k] + "/" + relative)))
            << relative << " differs between 1 and " << (k == 1 ? 2 : 4) << " threads";
      }
      ++(extension == ".csv" ? files : summaries);
    }
    // damage: runs, zones, three profiles; comparator: runs, statistics, curves; each
    // its summary.md and the folder's README.md.
    EXPECT_EQ(files, study == "damage" ? 5 : 3) << study;
    EXPECT_EQ(summaries, 2) << study;
  }
}

TEST(IdentifyStudyTest, BadStudyValuesStopBeforeAnyComputation) {
  const std::string directory = FreshDirectory("identify_study_bad");
  std::string text = kTinyStudyConfig;
  text.replace(text.find("omega_points: 4"), 15, "omega_points: 1");
  const std::string config = WriteConfig(directory, text);
  const std::string folder = directory + "/results";
  RunResult result = RunIdentify("study " + config + " --output " + folder);
  EXPECT_EQ(result.exit_code, 2) << result.output;
  EXPECT_NE(result.output.find(config +
                               ":14: study.relaxation.omega_points must lie in [2, 1000], got 1"),
            std::string::npos)
      << result.output;
  result = RunIdentify("study " + config + " --set study.relaxation.omega_points=4 --set " +
                       "'study.robustness.snr=[20, 0]' --output " + folder);
  EXPECT_EQ(result.exit_code, 2) << result.output;
  EXPECT_NE(result.output.find("--set study.robustness.snr=[20, 0]: study.robustness.snr must "
                               "hold SNRs > 0"),
            std::string::npos)
      << result.output;
  result = RunIdentify("study " + config +
                       " --set study.relaxation.omega_points=4 --set study.kind=every " +
                       "--output " + folder);
  EXPECT_EQ(result.exit_code, 2) << result.output;
  EXPECT_NE(
      result.output.find("--set study.kind=every: expected one of 'robustness', 'relaxation', "
                         "'cost_curves', 'all', 'damage', 'comparator', 'readme', got 'every'"),
      std::string::npos)
      << result.output;
  EXPECT_FALSE(fs::exists(folder));
}

TEST(IdentifyStudyTest, ADamageStudyOnABarItsTruthsAndSensorsDoNotFitStopsBeforeAnyRun) {
  const std::string directory = FreshDirectory("identify_study_damage_bar");
  const std::string config = WriteConfig(directory, kTinyStudyConfig);
  const std::string folder = directory + "/results";
  RunResult result = RunIdentify("study " + config + " --set study.kind=damage " +
                                 "--set model.length=0.8 --output " + folder);
  EXPECT_EQ(result.exit_code, 2) << result.output;
  EXPECT_NE(result.output.find(config + ": study.kind damage places its truth zones and sensors "
                                        "in m on the paper's bar; its run of the soft truth with "
                                        "interior sensors and 10 equal zones would fail on this "
                                        "config's bar: data.sensors[6] = 'e@0.9': the sensor lies "
                                        "outside the bar [0, 0.8] m"),
            std::string::npos)
      << result.output;
  result = RunIdentify("study " + config + " --set study.kind=damage --set model.elements=8 " +
                       "--output " + folder);
  EXPECT_EQ(result.exit_code, 2) << result.output;
  EXPECT_NE(result.output.find("its run of the soft truth with end sensors and 10 equal zones "
                               "would fail on this config's bar: model.zone_count must be "
                               "between 1 and model.elements = 8"),
            std::string::npos)
      << result.output;
  EXPECT_FALSE(fs::exists(folder));
}

}  // namespace
}  // namespace mcrewave

namespace mcrewave {
namespace {

TEST(IdentifyStudyDamageTest, TheDamageStudyRunsOnTheQuickCaseAndLocalisesWithInteriorSensors) {
  // The grid at SNR inf on the quick case (25 elements), zones merged, the 10 equal zones
  // by both functionals: 12 runs in about 6 s on 2 cores.
  const std::string folder = testing::FreshDirectory("identify_study_damage") + "/results";
  const testing::RunResult result = testing::RunIdentify(
      "study " + testing::SourcePath("configs/quick.yaml") + " -o " + folder +
      " --set study.kind=damage --set study.damage.snr=[.inf] --set study.damage.seeds=1"
      " --set zone_identification.merge_zones=true");
  ASSERT_EQ(result.exit_code, 0) << result.output;
  std::istringstream runs(testing::ReadText(folder + "/damage/runs.csv"));
  std::string line;
  std::getline(runs, line);
  EXPECT_EQ(line.rfind("run,truth,sensors,snr,seed,zoning,converged,", 0), 0u) << line;
  int rows = 0;
  while (std::getline(runs, line)) {
    ++rows;
    std::vector<std::string> fields;
    std::istringstream row(line);
    for (std::string field; std::getline(row, field, ',');) fields.push_back(field);
    ASSERT_GE(fields.size(), 9u) << line;
    EXPECT_EQ(fields[6], "1") << line;  // converged
    // Merging runs on the 10 equal zones only: 1 to 10 groups left; -1 per element.
    ASSERT_GE(fields.size(), 15u) << line;
    const int groups = std::stoi(fields[14]);
    // The 10 equal zones are also identified by least squares (ls_converged, field 19).
    // With the interior sensors, the truths the zones cannot represent (non-aligned, two
    // zones) are far better explained by the identified moduli than by the truth's in
    // series, by both functionals: the data cost ratio (reference_cost_ratio, field 18;
    // ls_reference_cost_ratio, field 24) measured 31 and 50 for the MCRE, 8.0 and 8.8
    // for least squares.
    ASSERT_EQ(fields.size(), 28u) << line;
    if (fields[5] == "10_equal") {
      EXPECT_GE(groups, 1) << line;
      EXPECT_LE(groups, 10) << line;
      EXPECT_EQ(fields[19], "1") << line;
      if (fields[2] == "interior" && fields[1] != "soft") {
        EXPECT_GT(std::stod(fields[18]), 4.0) << line;
        EXPECT_GT(std::stod(fields[24]), 4.0) << line;
      }
    } else {
      EXPECT_EQ(groups, -1) << line;
      EXPECT_EQ(fields[19], "") << line;
    }
    // With the interior sensors the error map peaks in an element (0.04 m, its
    // midpoint reported) that overlaps a zone of the truth (soft and non-aligned:
    // [0.6, 0.71] m; two zones: [0.15, 0.25] or [0.55, 0.65] m); measured 0.66 m for
    // all three (for the two zones, the stiff zone's edge element [0.64, 0.68]).
    if (fields[2] == "interior") {
      const double peak = std::stod(fields[8]);
      if (fields[1] == "two_zones") {
        EXPECT_TRUE((peak >= 0.13 && peak <= 0.27) || (peak >= 0.53 && peak <= 0.67)) << line;
      } else {
        EXPECT_GE(peak, 0.6) << line;
        EXPECT_LE(peak, 0.71) << line;
      }
    }
  }
  EXPECT_EQ(rows, 12);
  EXPECT_TRUE(std::filesystem::exists(folder + "/damage/summary.md"));
  EXPECT_TRUE(std::filesystem::exists(folder + "/damage/zones.csv"));
}

}  // namespace
}  // namespace mcrewave

namespace mcrewave {
namespace {

TEST(IdentifyStudyComparatorTest, BothFunctionalsOnTheSameDataWithEveryModelError) {
  // The quick case (25 elements, 300 steps), SNR inf and 20 with 2 seeds, every
  // model error: 3 data sets x 8 errors x 4 identifications.
  const std::string folder = testing::FreshDirectory("identify_study_comparator") + "/results";
  const testing::RunResult result = testing::RunIdentify(
      "study " + testing::SourcePath("configs/quick.yaml") + " -o " + folder +
      " --set study.kind=comparator --set study.comparator.snr=[.inf,20] --set "
      "study.comparator.seeds=2 --set study.threads=2");
  ASSERT_EQ(result.exit_code, 0) << result.output;
  for (const char* file : {"runs.csv", "statistics.csv", "curves.csv", "summary.md"}) {
    EXPECT_TRUE(fs::exists(folder + "/comparator/" + file)) << file;
  }
  std::istringstream runs(testing::ReadText(folder + "/comparator/runs.csv"));
  std::string line;
  std::getline(runs, line);
  int count = 0, converged = 0;
  for (; std::getline(runs, line); ++count) {
    std::vector<std::string> cells;
    std::istringstream row(line);
    for (std::string cell; std::getline(row, cell, ',');) cells.push_back(cell);
    ASSERT_GE(cells.size(), 11u) << line;
    if (cells[5] != "1") continue;
    ++converged;
    const double error = std::stod(cells[7]);
    // Noise-free on the right model: both functionals within the discretisation
    // bias of 25 elements against the 4x finer truth (measured: MCRE -8.1e-5, least
    // squares -6.6e-4, raw and pre-filtered alike).
    if (cells[0] == "none" && cells[1] == "inf") {
      EXPECT_LT(std::abs(error), cells[3] == "mcre" ? 4e-4 : 3e-3) << line;
    }
    // The soft zone by the clamp makes the bar softer on average: E below the reference.
    if (cells[0] == "soft_zone" && cells[1] == "inf") {
      EXPECT_LT(error, 0.0) << line;
    }
    // A spring of 10 E S / L at the clamp: the MCRE with the paper's measured clamp
    // (quick.yaml) does not trust it, least squares does (measured: MCRE -2.5e-4, least
    // squares -16.6 %).
    if (cells[0] == "support_10" && cells[1] == "inf") {
      if (cells[3] == "mcre") {
        EXPECT_LT(std::abs(error), 2.5e-3) << line;
      } else {
        EXPECT_LT(error, -0.1) << line;
      }
    }
  }
  EXPECT_EQ(count, 3 * 8 * 4);
  EXPECT_EQ(converged, count);
  if (result.output.find("gnuplot not found") == std::string::npos) {
    EXPECT_GT(fs::file_size(folder + "/comparator/comparator.png"), 10000u);
  }
}

TEST(IdentifyStudyComparatorTest, ATrustedClampContradictedByTheDataIsTreatedAsMeasured) {
  // The quick case with the default clamp (trusted, its weights and search), pre-filtered
  // data at SNR inf and 20 (2 seeds) of the rigid clamp and of a spring of 10 E S / L:
  // the MCRE tests u0 against f0 on every data set and switches on the spring's alone.
  const std::string folder =
      testing::FreshDirectory("identify_study_comparator_support") + "/results";
  const testing::RunResult result = testing::RunIdentify(
      "study " + testing::SourcePath("configs/quick.yaml") + " -o " + folder +
      " --set study.kind=comparator --set study.comparator.snr=[.inf,20] --set "
      "study.comparator.seeds=2 --set study.comparator.errors=[none,support_10] --set "
      "study.comparator.data=[prefilter] --set mcre.clamp=trusted --set mcre.w_u=1e-7 --set "
      "mcre.w_e=1e-7 --set mcre.w_r=1e-6 --set search.functional=pinned");
  ASSERT_EQ(result.exit_code, 0) << result.output;
  std::istringstream runs(testing::ReadText(folder + "/comparator/runs.csv"));
  std::string line;
  std::getline(runs, line);
  ASSERT_NE(line.find(",support_switched,support_statistic,support_weight,"), std::string::npos)
      << line;
  int count = 0;
  for (; std::getline(runs, line); ++count) {
    std::vector<std::string> cells;
    std::istringstream row(line);
    for (std::string cell; std::getline(row, cell, ',');) cells.push_back(cell);
    ASSERT_GE(cells.size(), 15u) << line;
    EXPECT_EQ(cells[5], "1") << line;
    const bool mcre = cells[3] == "mcre";
    const bool spring = cells[0] == "support_10";
    const double error = std::stod(cells[7]);
    EXPECT_EQ(cells[12], mcre && spring ? "1" : "0") << line;
    if (!mcre) {
      EXPECT_EQ(cells[13], "nan") << line;
      continue;
    }
    const double statistic = std::stod(cells[13]);
    // Measured: t 1.0e4 (SNR inf), 47 and 50 on the spring, 0, 0.14 and -0.35 on the
    // rigid clamp; the switched E -2.5e-4 (inf), +2.4e-3 and -2.8e-3 (SNR 20); least
    // squares -16.6 %.
    if (spring) {
      EXPECT_GT(statistic, 2.5) << line;
      EXPECT_LT(std::abs(error), cells[1] == "inf" ? 2.5e-3 : 1e-2) << line;
    } else {
      EXPECT_LT(statistic, 2.5) << line;
    }
  }
  EXPECT_EQ(count, 2 * 3 * 2);
}

TEST(IdentifyStudyComparatorTest, PreFilteredDataOnlyWithATrustedOrPinnedClamp) {
  // study.comparator.data [prefilter]: two identifications per data set; the MCRE with
  // the clamp trusted (f0 an output), then pinned (u0's datum the known 0, f0 a load),
  // on noise-free data of the quick case. The discretisation bias of 25 elements
  // against the 4x finer truth, measured: MCRE trusted -2.8e-4, pinned -1.5e-4 (one
  // valley), least squares -6.6e-4.
  struct Case {
    const char* settings;
    double mcre_bound;  // of |relative error of E|
    bool one_valley;    // the MCRE's scan must see a single valley
  };
  // The third case is the first's e^2 with the default global search: the scan on the
  // pinned search functional, then e^2 refined near its minimum; one valley, and the
  // minimiser the first case's scan of e^2 itself found (measured 3.3e-8 apart: from
  // their scans' different brackets, the secant stops on a step below
  // outer.relative_tolerance 1e-7).
  const Case cases[] = {
      {"mcre.clamp=trusted --set mcre.w_r=0.01", 3e-3, false},
      {"mcre.clamp=pinned --set mcre.w_u0=0.1 --set mcre.w_r=0.1", 1.5e-3, true},
      {"mcre.clamp=trusted --set mcre.w_r=0.01 --set search.functional=pinned", 3e-3, true}};
  std::vector<double> mcre_moduli;
  for (const auto& [settings, mcre_bound, one_valley] : cases) {
    const std::string folder =
        testing::FreshDirectory("identify_study_comparator_clamp") + "/results";
    const testing::RunResult result = testing::RunIdentify(
        "study " + testing::SourcePath("configs/quick.yaml") + " -o " + folder +
        " --set study.kind=comparator --set study.comparator.snr=[.inf] --set "
        "study.comparator.errors=[none] --set study.comparator.data=[prefilter] --set " +
        settings);
    ASSERT_EQ(result.exit_code, 0) << result.output;
    std::istringstream runs(testing::ReadText(folder + "/comparator/runs.csv"));
    std::string line;
    std::getline(runs, line);
    int count = 0;
    for (; std::getline(runs, line); ++count) {
      std::vector<std::string> cells;
      std::istringstream row(line);
      for (std::string cell; std::getline(row, cell, ',');) cells.push_back(cell);
      ASSERT_GE(cells.size(), 11u) << line;
      EXPECT_EQ(cells[4], "prefilter") << line;
      EXPECT_EQ(cells[5], "1") << line;
      const bool mcre = cells[3] == "mcre";
      EXPECT_LT(std::abs(std::stod(cells[7])), mcre ? mcre_bound : 3e-3) << settings << ": " << line;
      if (mcre && one_valley) {
        EXPECT_EQ(cells[8], "1") << line;
      }
      if (mcre) mcre_moduli.push_back(std::stod(cells[6]));
      // The search functional's minimiser, in two stages only: within the refinement's
      // window of E (measured 0.013 % apart).
      const bool two_stages = mcre && mcre_moduli.size() == 3;
      ASSERT_GE(cells.size(), 12u) << line;
      if (two_stages) {
        EXPECT_LT(std::abs(std::stod(cells[11]) / std::stod(cells[6]) - 1.0), 0.03) << line;
      } else {
        EXPECT_EQ(cells[11], "nan") << line;
      }
    }
    EXPECT_EQ(count, 2);
    const std::string curves = testing::ReadText(folder + "/comparator/curves.csv");
    EXPECT_EQ(curves.substr(0, curves.find('\n')),
              "model_error_index,snr,mcre_prefilter,least_squares_prefilter");
  }
  ASSERT_EQ(mcre_moduli.size(), 3u);
  EXPECT_NEAR(mcre_moduli[2] / mcre_moduli[0] - 1.0, 0.0, 1e-7);
}

}  // namespace
}  // namespace mcrewave
