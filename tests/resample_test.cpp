// Tests of the band-limited resampling (data/resample.h): exact on the data's own
// grid, the error on smooth signals up- and down-sampled, the window check.
#include "mcrewave/data/resample.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <utility>

namespace mcrewave {
namespace {

// A set of `samples` samples of step h from t = 0: sines at `frequency` [Hz] on every
// channel and on a strain sensor, starting at rest (sin(2 pi f t) vanishes at t = 0).
MeasurementSet Sines(double h, int samples, double frequency) {
  MeasurementSet set;
  set.time_step = h;
  Vector values(samples);
  for (int k = 0; k < samples; ++k) {
    const double t = k * h;
    values[k] =
        std::sin(2 * M_PI * frequency * t) + 0.3 * std::sin(2 * M_PI * 0.37 * frequency * t);
  }
  set.u0 = values;
  set.uL = 2.0 * values;
  set.f0 = -values;
  set.fL = 3.0 * values;
  set.sensors.push_back({"e@0.5", SensorKind::kStrain, 0.5, 1e-4 * values});
  return set;
}

double MaxError(const MeasurementSet& resampled, double frequency) {
  double worst = 0.0;
  // Away from both ends: the start from rest is a kink (its ringing decays over the
  // kernel's 8 lobes) and the last value is held past the end.
  const int samples = resampled.num_samples();
  for (int k = samples / 10; k < samples - samples / 10; ++k) {
    const double t = k * resampled.time_step;
    const double exact =
        std::sin(2 * M_PI * frequency * t) + 0.3 * std::sin(2 * M_PI * 0.37 * frequency * t);
    worst = std::max(worst, std::abs(resampled.uL[k] / 2.0 - exact));
    worst = std::max(worst, std::abs(resampled.sensors[0].values[k] / 1e-4 - exact));
  }
  return worst;
}

TEST(ResampleTest, TheDataOwnGridIsReproducedExactly) {
  const MeasurementSet data = Sines(1e-6, 200, 2e4);
  const MeasurementSet same = ResampleMeasurements(data, 1e-6, 200, "data.csv");
  EXPECT_EQ(same.uL, data.uL);
  EXPECT_EQ(same.sensors[0].values, data.sensors[0].values);
}

TEST(ResampleTest, UpSamplingASmoothSignalIsAccurate) {
  // Data at 2.5 us, content at 0.05 and 0.0185 of the sample rate, onto 1 us:
  // measured 6.9e-4 of the amplitude.
  const MeasurementSet data = Sines(2.5e-6, 400, 2e4);
  const MeasurementSet fine = ResampleMeasurements(data, 1e-6, 901, "data.csv");
  ASSERT_EQ(fine.num_samples(), 901);
  EXPECT_EQ(fine.time_step, 1e-6);
  EXPECT_LT(MaxError(fine, 2e4), 5e-3);
}

TEST(ResampleTest, DownSamplingFiltersBelowTheNewNyquistFrequency) {
  // Data at 0.4 us onto 1.2 us, content at 0.024 of the new rate (kept) plus a tone
  // at 0.6 of the new rate (above its Nyquist frequency: it must not fold back).
  MeasurementSet data = Sines(0.4e-6, 3000, 2e4);
  for (int k = 0; k < data.num_samples(); ++k) {
    data.uL[k] += 0.5 * std::sin(2 * M_PI * 5e5 * k * 0.4e-6);
  }
  const MeasurementSet coarse = ResampleMeasurements(data, 1.2e-6, 900, "data.csv");
  // Measured 9.4e-5 of the amplitude: the tone is gone, nothing folded back.
  EXPECT_LT(MaxError(coarse, 2e4), 9e-4);
}

TEST(ResampleTest, DataThatDoNotCoverTheWindowAreRefused) {
  const MeasurementSet data = Sines(1e-6, 100, 2e4);
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

// The bar's set is resampled as a table of its channels: each channel of
// ResampleMeasurements is the same bits as its column of ResampleChannelTable, up and
// down (the down-sampling's low-pass included), sensors after the four end channels.
TEST(ResampleTest, AChannelTableIsResampledAsTheBarsSet) {
  const MeasurementSet data = Sines(1e-6, 400, 2e4);
  ChannelTable table;
  table.time_step = data.time_step;
  table.samples = data.num_samples();
  table.names = {"fL", "tip", "gauge"};
  table.columns = {data.fL, data.uL, data.sensors[0].values};
  for (const auto& [step, samples] : {std::pair<double, int>{0.4e-6, 900},
                                      std::pair<double, int>{2.5e-6, 150}}) {
    const MeasurementSet set = ResampleMeasurements(data, step, samples, "data.csv");
    const ChannelTable resampled = ResampleChannelTable(table, step, samples, "data.csv");
    ASSERT_EQ(resampled.samples, samples);
    EXPECT_EQ(resampled.time_step, step);
    EXPECT_EQ(resampled.names, table.names);
    EXPECT_EQ(resampled.columns[0], set.fL) << step;
    EXPECT_EQ(resampled.columns[1], set.uL) << step;
    EXPECT_EQ(resampled.columns[2], set.sensors[0].values) << step;
  }
  EXPECT_THROW(ResampleChannelTable(table, 1e-6, 500, "data.csv"), InputError);
}

}  // namespace
}  // namespace mcrewave
