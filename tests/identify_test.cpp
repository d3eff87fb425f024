// End-to-end tests of the identify binary: it is run as a user runs it.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <string>
#include <utility>
#include <vector>

#include "identify_binary.h"
#include "mcrewave/app/config.h"
#include "mcrewave/app/identification_run.h"
#include "mcrewave/data/measurement.h"

namespace mcrewave {
namespace {

using testing::FreshDirectory;
using testing::RunIdentify;
using testing::RunResult;
using testing::SourcePath;

TEST(IdentifyTest, HelpAndVersion) {
  const RunResult help = RunIdentify("--help");
  EXPECT_EQ(help.exit_code, 0);
  EXPECT_NE(help.output.find("simulate"), std::string::npos) << help.output;
  EXPECT_NE(help.output.find("run"), std::string::npos) << help.output;
  const RunResult version = RunIdentify("--version");
  EXPECT_EQ(version.exit_code, 0);
  EXPECT_NE(version.output.find("mcrewave"), std::string::npos) << version.output;
}

TEST(IdentifyTest, BadCommandLinesExitWithTwoAndOneLine) {
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"run", "config is required"},
      {"bogus", "bogus"},
      {"run " + SourcePath("configs/quick.yaml") + " -v -q", "--verbose excludes --quiet"},
      {"simulate " + SourcePath("configs/quick.yaml"), "--output is required"},
  };
  for (const auto& [arguments, reason] : cases) {
    const RunResult run = RunIdentify(arguments);
    EXPECT_EQ(run.exit_code, 2) << arguments << "\n" << run.output;
    EXPECT_EQ(run.output.rfind("error: ", 0), 0u) << run.output;
    EXPECT_NE(run.output.find(reason), std::string::npos) << run.output;
    EXPECT_EQ(std::count(run.output.begin(), run.output.end(), '\n'), 1) << run.output;
  }
}

// simulate refuses synthetic data out of double range with exit 2, one line and
// no file.
TEST(IdentifyTest, SimulateRefusesNonFiniteData) {
  const std::string dir = FreshDirectory("identify_simulate_bad_input");
  const std::string quick = SourcePath("configs/quick.yaml");
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"simulate " + quick + " --set data.snr=1e-307 -o " + dir + "/out.csv",
       "the synthetic channel 'f0' is not finite: load.amplitude (1000 N) or the noise of "
       "data.snr (1e-307) lies beyond double range"},
      {"simulate " + quick + " --set load.amplitude=1e308 -o " + dir + "/out.csv",
       "the synthetic channel 'u0' is not finite: load.amplitude (1e+308 N)"},
  };
  for (const auto& [arguments, reason] : cases) {
    const RunResult run = RunIdentify(arguments + " -q");
    EXPECT_EQ(run.exit_code, 2) << arguments << "\n" << run.output;
    EXPECT_NE(run.output.find(reason), std::string::npos) << run.output;
    EXPECT_EQ(std::count(run.output.begin(), run.output.end(), '\n'), 1) << run.output;
  }
  EXPECT_TRUE(std::filesystem::is_empty(dir));
}

TEST(IdentifyTest, OverridesMayComeBeforeTheConfig) {
  const std::string dir = FreshDirectory("identify_set_first");
  const RunResult run = RunIdentify("simulate --set time.window=0.144e-3 --set data.snr=.inf " +
                                    SourcePath("configs/quick.yaml") + " -o " + dir + "/out.csv");
  ASSERT_EQ(run.exit_code, 0) << run.output;
  EXPECT_EQ(ReadMeasurementCsv(dir + "/out.csv").num_samples(), 101);
}

TEST(IdentifyTest, PrintsADefaultConfigThatSimulateAccepts) {
  const std::string dir = FreshDirectory("identify_default_config");
  const RunResult printed = RunIdentify("--print-default-config > " + dir + "/default.yaml");
  ASSERT_EQ(printed.exit_code, 0) << printed.output;
  const RunResult simulated = RunIdentify(
      "simulate " + dir + "/default.yaml --set time.window=0.036e-3 -o " + dir + "/out.csv");
  EXPECT_EQ(simulated.exit_code, 0) << simulated.output;
  EXPECT_EQ(ReadMeasurementCsv(dir + "/out.csv").num_samples(), 101);
}

TEST(IdentifyTest, SimulateWritesTheChannelSetOfThePaperCase) {
  const std::string dir = FreshDirectory("identify_simulate");
  const std::string csv = dir + "/paper.csv";
  const RunResult run = RunIdentify("simulate " + SourcePath("configs/paper_bar.yaml") +
                                    " --set data.truth_refinement=1 --set "
                                    "data.sensors=[u@0.25,e@0.65] --output " +
                                    csv);
  ASSERT_EQ(run.exit_code, 0) << run.output;
  const ChannelSet measurements = ReadMeasurementCsv(csv);
  EXPECT_EQ(measurements.num_samples(), 1751);
  EXPECT_NEAR(measurements.time_step, 0.36e-6, 1e-15);
  // Every channel holds the bits of the library's synthetic measurements of the
  // same config (written with 17 significant digits).
  const ChannelSet library =
      LoadMeasurements(LoadConfig(SourcePath("configs/paper_bar.yaml"),
                                  {"data.truth_refinement=1", "data.sensors=[u@0.25,e@0.65]"}));
  EXPECT_EQ(measurements.Values("u0"), library.Values("u0"));
  EXPECT_EQ(measurements.Values("uL"), library.Values("uL"));
  EXPECT_EQ(measurements.Values("f0"), library.Values("f0"));
  EXPECT_EQ(measurements.Values("fL"), library.Values("fL"));
  const std::vector<BarSensor> measured_sensors = BarSensors(measurements);
  const std::vector<BarSensor> library_sensors = BarSensors(library);
  ASSERT_EQ(measured_sensors.size(), 2u);
  ASSERT_EQ(library_sensors.size(), 2u);
  for (int i = 0; i < 2; ++i) {
    const Channel& measured =
        measurements.channels[static_cast<std::size_t>(measured_sensors[i].index)];
    const Channel& simulated = library.channels[static_cast<std::size_t>(library_sensors[i].index)];
    EXPECT_EQ(measured.name, simulated.name);
    EXPECT_EQ(measured.values, simulated.values);
  }
  for (int j = 0; j < measurements.num_samples(); ++j) {
    ASSERT_EQ(measurements.Time(j), library.Time(j)) << "sample " << j;
  }
  // Nothing but the result is left in the folder (no temporary file).
  int files = 0;
  for (const auto& entry : std::filesystem::directory_iterator(dir)) {
    EXPECT_EQ(entry.path().filename(), "paper.csv");
    ++files;
  }
  EXPECT_EQ(files, 1);
  // The same config and seed give the same file.
  const std::string again = dir + "/again.csv";
  ASSERT_EQ(RunIdentify("simulate " + SourcePath("configs/paper_bar.yaml") +
                        " --set data.truth_refinement=1 --output " + again)
                .exit_code,
            0);
  EXPECT_EQ(ReadMeasurementCsv(again).Values("uL"), measurements.Values("uL"));
}

TEST(IdentifyTest, BadConfigFailsWithOneLineNamingFileLineAndKeyAndWritesNothing) {
  const std::string dir = FreshDirectory("identify_bad_config");
  const std::string config = dir + "/bad.yaml";
  std::ofstream(config) << "model:\n  elements: 100\n  lenght: 2\n";
  const RunResult run = RunIdentify("simulate " + config + " -o " + dir + "/out.csv");
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_NE(run.output.find(config + ":3"), std::string::npos) << run.output;
  EXPECT_NE(run.output.find("model.length"), std::string::npos) << run.output;
  EXPECT_FALSE(std::filesystem::exists(dir + "/out.csv"));
}

TEST(IdentifyTest, BadOverrideAndMissingConfigAreRefused) {
  const RunResult override_run = RunIdentify("simulate " + SourcePath("configs/paper_bar.yaml") +
                                             " --set time.theta=2 -o /tmp/never.csv");
  EXPECT_EQ(override_run.exit_code, 2);
  EXPECT_NE(override_run.output.find("time.theta"), std::string::npos) << override_run.output;
  const RunResult missing = RunIdentify("simulate /nonexistent/config.yaml -o /tmp/never.csv");
  EXPECT_EQ(missing.exit_code, 2);
  EXPECT_NE(missing.output.find("/nonexistent/config.yaml"), std::string::npos);
}

// An output file in a folder that does not exist is bad input, refused before the
// simulation.
TEST(IdentifyTest, UnwritableOutputIsReportedNotCrashed) {
  const RunResult run = RunIdentify("simulate " + SourcePath("configs/paper_bar.yaml") +
                                    " --set data.truth_refinement=1 -o /nonexistent/dir/out.csv");
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_NE(run.output.find(
                "error: output file /nonexistent/dir/out.csv: /nonexistent/dir is not a folder\n"),
            std::string::npos)
      << run.output;
  // Nothing was simulated: not even the config's summary line was logged.
  EXPECT_EQ(run.output.find(" elements, "), std::string::npos) << run.output;
}

}  // namespace
}  // namespace mcrewave
