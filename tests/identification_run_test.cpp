// Tests of the identification run's search functional on a coarser grid (SearchData,
// search.time_step_factor): the resampled data, and the paper's case identified with the
// search on every fourth step against the search on the data's own grid.
#include "mcrewave/app/identification_run.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>

#include "identify_binary.h"
#include "mcrewave/app/config.h"

namespace mcrewave {
namespace {

TEST(SearchDataTest, ResamplesToTheFactorsStepAndKeepsEnoughSteps) {
  // The quick case: 300 steps of 1.44 us, pre-filtered as identify run does.
  const Config config = LoadConfig(testing::SourcePath("configs/quick.yaml"), {});
  const IdentificationRun run = RunIdentification(config, LoadMeasurements(config));
  ASSERT_TRUE(run.IsUsable()) << run.outer.FullReport();
  const ChannelSet& data = run.data;
  ASSERT_EQ(data.num_steps(), 300);

  SearchOptions search;
  EXPECT_EQ(search.time_step_factor, 1);
  // Factor 1: the data as they are.
  const ChannelSet same = SearchData(data, search);
  ASSERT_EQ(same.channels.size(), data.channels.size());
  for (std::size_t c = 0; c < data.channels.size(); ++c) {
    EXPECT_EQ(same.channels[c].values, data.channels[c].values) << data.channels[c].name;
  }

  search.time_step_factor = 3;
  const ChannelSet coarse = SearchData(data, search);
  EXPECT_EQ(coarse.num_steps(), 100);
  EXPECT_DOUBLE_EQ(coarse.time_step, 3.0 * data.time_step);
  ASSERT_EQ(coarse.channels.size(), data.channels.size());
  for (std::size_t c = 0; c < data.channels.size(); ++c) {
    EXPECT_EQ(coarse.channels[c].name, data.channels[c].name);
  }
  // The loaded end's channels, every third sample: measured 2.2e-3 (uL) and 2.3e-3 (fL)
  // of the channel's largest value, the down-sampling's low-pass at 0.4 / (3 h) on the
  // pre-filtered band (the clamp's u0 and f0, noise and its sharp reflections, move by
  // more).
  for (const char* name : {"uL", "fL"}) {
    const Vector& given = data.Values(name);
    const Vector& resampled = coarse.Values(name);
    double worst = 0.0;
    for (int k = 0; k <= coarse.num_steps(); ++k) {
      worst = std::max(worst, std::abs(resampled[k] - given[3 * k]));
    }
    EXPECT_LT(worst, 1e-2 * given.cwiseAbs().maxCoeff()) << name;
  }

  // 300 / 64 = 4: the factor is lowered to keep kSearchMinimumSteps steps.
  search.time_step_factor = 64;
  EXPECT_EQ(SearchData(data, search).num_steps(), 300 / (300 / kSearchMinimumSteps));
}

TEST(SearchDataTest, TheSearchOnEveryFourthStepPlacesTheSameWindowAndFindsTheSameModulus) {
  // The paper's case (1750 steps, SNR 2.5): its data and model as identify run takes them.
  const Config given = LoadConfig(testing::SourcePath("configs/paper_bar.yaml"),
                                  {"output.curve_points=5", "uncertainty.samples=2"});
  const IdentificationRun run = RunIdentification(given, LoadMeasurements(given));
  ASSERT_TRUE(run.IsUsable()) << run.outer.FullReport();
  ASSERT_TRUE(IdentifiesInTwoStages(run.config, *run.model));
  McreIdentification fine, coarse;
  for (const int factor : {1, 4}) {
    Config config = run.config;
    config.search.time_step_factor = factor;
    (factor == 1 ? fine : coarse) = IdentifyWithMcre(config, *run.model, run.data);
  }
  for (const McreIdentification* identification : {&fine, &coarse}) {
    ASSERT_TRUE(identification->outer.IsSolutionUsable()) << identification->outer.FullReport();
    EXPECT_TRUE(identification->outer.scan_of_search) << identification->outer.FullReport();
    EXPECT_EQ(identification->outer.local_minima, 1) << identification->outer.FullReport();
  }
  // Measured: the search's minimiser 0.023 % apart (the window is +- 3 %), E 1.9e-10
  // apart (both refined to outer.relative_tolerance 1e-7).
  EXPECT_NEAR(coarse.outer.search_modulus / fine.outer.search_modulus, 1.0, 2e-3);
  EXPECT_NEAR(coarse.outer.modulus / fine.outer.modulus, 1.0, 2e-7);
  EXPECT_EQ(fine.outer.modulus, run.identified_modulus());
}

}  // namespace
}  // namespace mcrewave
