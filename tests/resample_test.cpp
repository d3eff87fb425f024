// Tests of the band-limited resampling (data/resample.h): exact on the data's own
// grid, the error on smooth signals up- and down-sampled, the window check.
#include "mcrewave/data/resample.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <utility>

#include "mcrewave/data/measurement.h"

namespace mcrewave {
namespace {

// A set of `samples` samples of step h from t = 0: sines at `frequency` [Hz] on every
// channel and on a strain sensor, starting at rest (sin(2 pi f t) vanishes at t = 0).
ChannelSet Sines(double h, int samples, double frequency) {
  Vector values(samples);
  for (int k = 0; k < samples; ++k) {
    const double t = k * h;
    values[k] =
        std::sin(2 * M_PI * frequency * t) + 0.3 * std::sin(2 * M_PI * 0.37 * frequency * t);
  }
  ChannelSet set = BarChannelSet(0.0, h, values, 2.0 * values, -values, 3.0 * values);
  set.Add("e@0.5", ChannelKind::kStrain, 1e-4 * values);
  return set;
}

double MaxError(const ChannelSet& resampled, double frequency) {
  double worst = 0.0;
  // Away from both ends: the start from rest is a kink (its ringing decays over the
  // kernel's 8 lobes) and the last value is held past the end.
  const int samples = resampled.num_samples();
  for (int k = samples / 10; k < samples - samples / 10; ++k) {
    const double t = k * resampled.time_step;
    const double exact =
        std::sin(2 * M_PI * frequency * t) + 0.3 * std::sin(2 * M_PI * 0.37 * frequency * t);
    worst = std::max(worst, std::abs(resampled.Values("uL")[k] / 2.0 - exact));
    worst = std::max(worst, std::abs(resampled.Values("e@0.5")[k] / 1e-4 - exact));
  }
  return worst;
}

TEST(ResampleTest, TheDataOwnGridIsReproducedExactly) {
  const ChannelSet data = Sines(1e-6, 200, 2e4);
  const ChannelSet same = ResampleMeasurements(data, 1e-6, 200, "data.csv");
  EXPECT_EQ(same.Values("uL"), data.Values("uL"));
  EXPECT_EQ(same.Values("e@0.5"), data.Values("e@0.5"));
}

TEST(ResampleTest, UpSamplingASmoothSignalIsAccurate) {
  // Data at 2.5 us, content at 0.05 and 0.0185 of the sample rate, onto 1 us:
  // measured 6.9e-4 of the amplitude.
  const ChannelSet data = Sines(2.5e-6, 400, 2e4);
  const ChannelSet fine = ResampleMeasurements(data, 1e-6, 901, "data.csv");
  ASSERT_EQ(fine.num_samples(), 901);
  EXPECT_EQ(fine.time_step, 1e-6);
  EXPECT_LT(MaxError(fine, 2e4), 5e-3);
}

TEST(ResampleTest, DownSamplingFiltersBelowTheNewNyquistFrequency) {
  // Data at 0.4 us onto 1.2 us, content at 0.024 of the new rate (kept) plus a tone
  // at 0.6 of the new rate (above its Nyquist frequency: it must not fold back).
  ChannelSet data = Sines(0.4e-6, 3000, 2e4);
  for (int k = 0; k < data.num_samples(); ++k) {
    data.Values("uL")[k] += 0.5 * std::sin(2 * M_PI * 5e5 * k * 0.4e-6);
  }
  const ChannelSet coarse = ResampleMeasurements(data, 1.2e-6, 900, "data.csv");
  // Measured 9.4e-5 of the amplitude: the tone is gone, nothing folded back.
  EXPECT_LT(MaxError(coarse, 2e4), 9e-4);
}

TEST(ResampleTest, DataThatDoNotCoverTheWindowAreRefused) {
  const ChannelSet data = Sines(1e-6, 100, 2e4);
  try {
    ResampleMeasurements(data, 2e-6, 60, "short.csv");
    ADD_FAILURE() << "no InputError";
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what())
                  .find("short.csv: the data span [0, 9.9e-05] s does not "
                        "cover the model's window [0, 0.000118] s"),
              std::string::npos)
        << error.what();
  }
}

// A record that starts after t = 0 (a shot whose trigger came after the impact):
// refused, naming the way out, unless at_rest_before; then the samples before it are
// 0 and the record's own samples (on the grid) are kept to the bit.
TEST(ResampleTest, ARecordStartingLateIsAtRestBeforeItWhenAllowed) {
  ChannelSet data = Sines(1e-6, 100, 2e4);
  data.start_time = 20e-6;
  try {
    ResampleMeasurements(data, 1e-6, 100, "late.csv");
    ADD_FAILURE() << "no InputError";
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what()).find("data.at_rest_before_record"), std::string::npos)
        << error.what();
  }
  const ChannelSet late = ResampleMeasurements(data, 1e-6, 100, "late.csv", true);
  for (int k = 0; k < 20; ++k) EXPECT_EQ(late.Values("uL")[k], 0.0) << k;
  for (int k = 20; k < 100; ++k) EXPECT_EQ(late.Values("uL")[k], data.Values("uL")[k - 20]) << k;
}

// Any channel set is resampled channel by channel: each channel of a set of other
// names (a structure given by matrices) is the same bits as the bar's channel it
// copies, up and down (the down-sampling's low-pass included), names and kinds kept.
TEST(ResampleTest, AChannelTableIsResampledAsTheBarsSet) {
  const ChannelSet data = Sines(1e-6, 400, 2e4);
  ChannelSet table;
  table.time_step = data.time_step;
  table.Add("fL", ChannelKind::kForce, data.Values("fL"));
  table.Add("tip", ChannelKind::kDisplacement, data.Values("uL"));
  table.Add("gauge", ChannelKind::kStrain, data.Values("e@0.5"));
  for (const auto& [step, samples] : {std::pair<double, int>{0.4e-6, 900},
                                      std::pair<double, int>{2.5e-6, 150}}) {
    const ChannelSet set = ResampleMeasurements(data, step, samples, "data.csv");
    const ChannelSet resampled = ResampleMeasurements(table, step, samples, "data.csv");
    ASSERT_EQ(resampled.num_samples(), samples);
    EXPECT_EQ(resampled.time_step, step);
    ASSERT_EQ(resampled.channels.size(), 3u);
    for (std::size_t c = 0; c < 3; ++c) {
      EXPECT_EQ(resampled.channels[c].name, table.channels[c].name);
      EXPECT_EQ(resampled.channels[c].kind, table.channels[c].kind);
    }
    EXPECT_EQ(resampled.channels[0].values, set.Values("fL")) << step;
    EXPECT_EQ(resampled.channels[1].values, set.Values("uL")) << step;
    EXPECT_EQ(resampled.channels[2].values, set.Values("e@0.5")) << step;
  }
  EXPECT_THROW(ResampleMeasurements(table, 1e-6, 500, "data.csv"), InputError);
}

}  // namespace
}  // namespace mcrewave
