#include "mcrewave/data/measurement.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include "file_fixture.h"
#include "mcrewave/core/types.h"

namespace mcrewave {
namespace {

// Writes measurement files into a fresh directory of its own.
class MeasurementTest : public FileFixture {
 protected:
  MeasurementTest() : FileFixture("measurement") {}

  // Writes `content` as data.csv and expects ReadMeasurementCsv to throw an
  // InputError whose message starts with "<path>:<line>: " and contains `what`.
  void ExpectReadError(const std::string& content, int line, const std::string& what) const {
    const std::string path = WriteFile("data.csv", content);
    try {
      ReadMeasurementCsv(path);
      ADD_FAILURE() << "no InputError thrown for:\n" << content;
    } catch (const InputError& error) {
      const std::string message = error.what();
      EXPECT_EQ(message.rfind(path + ":" + std::to_string(line) + ": ", 0), 0u) << message;
      EXPECT_NE(message.find(what), std::string::npos) << message << "\nlacks: " << what;
    }
  }
};

// A set whose values exercise full precision: irrational-looking, tiny, huge, signed.
ChannelSet MakeSet(int samples, double start_time, double time_step) {
  ChannelSet set = BarChannelSet(start_time, time_step, Vector(samples), Vector(samples),
                                 Vector(samples), Vector(samples));
  for (int k = 0; k < samples; ++k) {
    set.Values("u0")[k] = std::sin(0.1 * k) * 1e-7 / 3.0;
    set.Values("uL")[k] = -std::exp(-0.01 * k) * 1e-300;
    set.Values("f0")[k] = std::cos(0.37 * k) * 1e3 + 1e-9;
    set.Values("fL")[k] = (k % 7) * 123456789.123456789 - 1.0 / (k + 1.0);
  }
  return set;
}

void ExpectBitwiseEqual(const Vector& expected, const Vector& actual) {
  ASSERT_EQ(expected.size(), actual.size());
  for (Eigen::Index k = 0; k < expected.size(); ++k) {
    ASSERT_EQ(expected[k], actual[k]) << "entry " << k;
  }
}

TEST_F(MeasurementTest, WriteThenReadIsExact) {
  for (const auto& [start_time, time_step] :
       std::vector<std::pair<double, double>>{{0.0, 0.36e-6}, {1.25e-3, 1.0 / 3.0 * 1e-6}}) {
    const ChannelSet written = MakeSet(1751, start_time, time_step);
    const std::string path = PathOf("round_trip.csv");
    WriteMeasurementCsv(written, path);
    const ChannelSet read = ReadMeasurementCsv(path);
    EXPECT_EQ(read.start_time, written.start_time);
    EXPECT_EQ(read.time_step, written.time_step);
    ExpectBitwiseEqual(written.Values("u0"), read.Values("u0"));
    ExpectBitwiseEqual(written.Values("uL"), read.Values("uL"));
    ExpectBitwiseEqual(written.Values("f0"), read.Values("f0"));
    ExpectBitwiseEqual(written.Values("fL"), read.Values("fL"));
  }
}

TEST_F(MeasurementTest, WrittenFileStartsWithTheHeader) {
  const std::string path = PathOf("header.csv");
  WriteMeasurementCsv(MakeSet(3, 0.0, 1e-6), path);
  std::ifstream file(path);
  std::string first_line;
  std::getline(file, first_line);
  EXPECT_EQ(first_line, "t,u0,uL,f0,fL");
}

TEST_F(MeasurementTest, WindowsLineEndsByteOrderMarkAndSpacesAreAccepted) {
  const std::string path = WriteFile(
      "windows.csv",
      "\xEF\xBB\xBFt,u0,uL,f0,fL \r\n0, 1,2 ,3,4\r\n1e-6,5,6,7,8\r\n2e-6,9,10,11,12\r\n\r\n\r\n");
  const ChannelSet set = ReadMeasurementCsv(path);
  ASSERT_EQ(set.num_samples(), 3);
  EXPECT_EQ(set.start_time, 0.0);
  EXPECT_DOUBLE_EQ(set.time_step, 1e-6);
  EXPECT_EQ(set.Values("u0")[0], 1.0);
  EXPECT_EQ(set.Values("uL")[0], 2.0);
  EXPECT_EQ(set.Values("f0")[2], 11.0);
  EXPECT_EQ(set.Values("fL")[2], 12.0);
}

TEST_F(MeasurementTest, BadHeader) {
  ExpectReadError("time,u\n0,1,2,3,4\n1,1,2,3,4\n", 1,
                  "column 1 'time': not a channel name (t, u0, uL, f0, fL, u@X or e@X");
}

TEST_F(MeasurementTest, ChannelsInAnyOrderWithInteriorSensors) {
  const std::string path = WriteFile(
      "sensors.csv",
      "fL,t,u@0.25,uL,e@0.65,f0,u0\n1,0,0.5,2,-1e-4,3,4\n5,1e-6,0.6,6,-2e-4,7,8\n"
      "9,2e-6,0.7,10,-3e-4,11,12\n");
  const ChannelSet set = ReadMeasurementCsv(path);
  ASSERT_EQ(set.num_samples(), 3);
  EXPECT_EQ(set.Values("fL")[1], 5.0);
  EXPECT_EQ(set.Values("uL")[2], 10.0);
  EXPECT_EQ(set.Values("f0")[0], 3.0);
  EXPECT_EQ(set.Values("u0")[2], 12.0);
  const std::vector<BarSensor> sensors = BarSensors(set);
  ASSERT_EQ(sensors.size(), 2u);
  EXPECT_EQ(set.channels[sensors[0].index].name, "u@0.25");
  EXPECT_EQ(sensors[0].kind, SensorKind::kDisplacement);
  EXPECT_EQ(sensors[0].position, 0.25);
  EXPECT_EQ(set.channels[sensors[0].index].values[2], 0.7);
  EXPECT_EQ(sensors[1].kind, SensorKind::kStrain);
  EXPECT_EQ(sensors[1].position, 0.65);
  EXPECT_EQ(set.channels[sensors[1].index].values[1], -2e-4);
  // The kinds, from the names.
  EXPECT_EQ(set.channels[set.Find("f0")].kind, ChannelKind::kForce);
  EXPECT_EQ(set.channels[set.Find("u0")].kind, ChannelKind::kDisplacement);
  EXPECT_EQ(set.channels[sensors[1].index].kind, ChannelKind::kStrain);
  // Written back in the canonical order, read back bit for bit.
  const std::string copy = PathOf("copy.csv");
  WriteMeasurementCsv(set, copy);
  const ChannelSet again = ReadMeasurementCsv(copy);
  EXPECT_EQ(again.Values("e@0.65"), set.Values("e@0.65"));
  EXPECT_EQ(again.time_step, set.time_step);
  std::ifstream file(copy);
  std::string header;
  std::getline(file, header);
  EXPECT_EQ(header, "t,u0,uL,f0,fL,u@0.25,e@0.65");
}

TEST_F(MeasurementTest, MalformedDuplicatedAndMissingChannelsAreRefusedOnTheHeaderLine) {
  const std::string rows = "\n0,1,2,3,4,5\n1,1,2,3,4,5\n";
  ExpectReadError("t,u0,uL,f0,fL,u@abc" + rows, 1, "the position X of 'u@abc'");
  ExpectReadError("t,u0,uL,f0,fL,x@1" + rows, 1, "column 6 'x@1': not a channel name");
  ExpectReadError("t,u0,uL,f0,fL,u@" + rows, 1, "the position X of 'u@'");
  ExpectReadError("t,u0,uL,f0,fL,e@-0.1" + rows, 1, "must be a finite number >= 0");
  ExpectReadError("t,u0,uL,f0,fL,uL" + rows, 1, "column 6 'uL' repeats column 3 'uL'");
  ExpectReadError("t,u0,uL,f0,fL,u@0.5,u@0.50\n0,1,2,3,4,5,6\n1,1,2,3,4,5,6\n", 1,
                  "column 7 'u@0.50' repeats column 6 'u@0.5'");
  ExpectReadError("t,u0,uL,f0,u@0.5\n0,1,2,3,4\n1,1,2,3,4\n", 1, "lacks the column 'fL'");
  ExpectReadError("t,u0,uL,f0,fL,e@0.5\n0,1,2,3,4,5\n1,1,2,3,4,x\n", 3,
                  "column 'e@0.5': 'x' is not a number");
}

TEST_F(MeasurementTest, EmptyFile) {
  ExpectReadError("", 1, "expected a header naming the columns: t,u0,uL,f0,fL in any order");
  ExpectReadError("", 1, "got an empty file");
}

TEST_F(MeasurementTest, WrongColumnCount) {
  ExpectReadError("t,u0,uL,f0,fL\n0,1,2,3,4\n1,1,2,3\n", 3, "expected 5 columns, got 4");
  ExpectReadError("t,u0,uL,f0,fL\n0,1,2,3,4\n1,1,2,3,4,5\n", 3, "expected 5 columns, got 6");
}

TEST_F(MeasurementTest, NonNumber) {
  ExpectReadError("t,u0,uL,f0,fL\n0,1,2,3,4\n1,1,2x,3,4\n", 3, "column 'uL': '2x' is not a number");
  ExpectReadError("t,u0,uL,f0,fL\n0,1,,3,4\n1,1,2,3,4\n", 2, "column 'uL': '' is not a number");
}

TEST_F(MeasurementTest, NanValue) {
  ExpectReadError("t,u0,uL,f0,fL\n0,1,2,3,4\n1,1,2,nan,4\n", 3,
                  "column 'f0': 'nan' is not a finite number");
}

TEST_F(MeasurementTest, InfiniteValue) {
  ExpectReadError("t,u0,uL,f0,fL\n0,1,2,3,4\n1,1,2,3,-inf\n", 3,
                  "column 'fL': '-inf' is not a finite number");
  ExpectReadError("t,u0,uL,f0,fL\n0,1e999,2,3,4\n1,1,2,3,4\n", 2,
                  "column 'u0': '1e999' is not a finite number");
}

TEST_F(MeasurementTest, TimeNotIncreasing) {
  ExpectReadError("t,u0,uL,f0,fL\n0,1,2,3,4\n1,1,2,3,4\n2,1,2,3,4\n2,1,2,3,4\n", 5,
                  "time is not strictly increasing");
}

TEST_F(MeasurementTest, NonUniformTime) {
  ExpectReadError("t,u0,uL,f0,fL\n0,1,2,3,4\n1,1,2,3,4\n2,1,2,3,4\n3.5,1,2,3,4\n", 5,
                  "time step 1.5 s (from t = 2 s on the previous row), expected the file's step "
                  "1 s (the median step) within 1e-6 relative");
}

// A file of `rows` data rows at t = 0.5 k s, the values of the rows with k in
// `skipped` left out (so it holds rows - skipped.size() rows) and, with
// `extra_time` >= 0, one more row at that time in its place.
std::string UniformFile(int rows, const std::vector<int>& skipped, double extra_time = -1.0) {
  std::string content = "t,u0,uL,f0,fL\n";
  for (int k = 0; k < rows; ++k) {
    const double time = 0.5 * k;  // [s]
    if (extra_time >= 0.0 && extra_time < time && extra_time > time - 0.5) {
      content += std::to_string(extra_time) + ",1,2,3,4\n";
    }
    if (std::find(skipped.begin(), skipped.end(), k) != skipped.end()) continue;
    content += std::to_string(time) + ",1,2,3,4\n";
  }
  return content;
}

// One sample missing in the middle: the row after the gap (t = 19.5 s, data row 38,
// line 40) is reported, with the step found there and the expected one.
TEST_F(MeasurementTest, MissingSampleIsReportedWhereItsGapEnds) {
  ExpectReadError(UniformFile(101, {38}), 40,
                  "time step 1 s (from t = 18.5 s on the previous row), expected the file's step "
                  "0.5 s (the median step)");
  // The second sample missing: the first step is the bad one, reported at line 3.
  ExpectReadError(UniformFile(101, {1}), 3, "time step 1 s (from t = 0 s on the previous row)");
  // The last sample but one missing: the last row, line 101.
  ExpectReadError(UniformFile(101, {99}), 101, "time step 1 s (from t = 49 s on the previous row)");
  // A row too many at t = 30.25 s, after t = 30 s (data row 60): line 63.
  ExpectReadError(UniformFile(101, {}, 30.25), 63,
                  "time step 0.25 s (from t = 30 s on the previous row), expected the file's "
                  "step 0.5 s");
}

TEST_F(MeasurementTest, UniformFileIsRead) {
  const ChannelSet set = ReadMeasurementCsv(WriteFile("data.csv", UniformFile(101, {})));
  EXPECT_EQ(set.num_steps(), 100);
  EXPECT_EQ(set.time_step, 0.5);
}

TEST_F(MeasurementTest, OnlyOneRow) {
  ExpectReadError("t,u0,uL,f0,fL\n0,1,2,3,4\n", 2, "expected at least 2 data rows, got 1");
}

TEST_F(MeasurementTest, HeaderOnly) {
  ExpectReadError("t,u0,uL,f0,fL\n", 1, "expected at least 2 data rows, got 0");
}

TEST_F(MeasurementTest, EmptyLineBetweenRows) {
  ExpectReadError("t,u0,uL,f0,fL\n0,1,2,3,4\n\n1,1,2,3,4\n", 3, "empty line");
}

// Found while writing the CSV fuzzer: finite times whose span overflows a double
// gave an infinite time step.
TEST_F(MeasurementTest, TimeSpanTooWideForADouble) {
  ExpectReadError("t,u0,uL,f0,fL\n-1e308,0,0,0,0\n1e308,0,0,0,0\n", 3,
                  "time span -1e+308 s to 1e+308 s is too wide for a double");
}

// A smooth set with the clamped end's u0 at zero, as `identify simulate` writes
// clean data.
ChannelSet SmoothSet(int samples) {
  ChannelSet set = BarChannelSet(0.0, 1e-6, Vector::Zero(samples), Vector(samples), Vector(samples),
                                 Vector(samples));
  for (int k = 0; k < samples; ++k) {
    set.Values("uL")[k] = 1e-6 * std::sin(0.05 * k);
    set.Values("f0")[k] = -1e3 * std::sin(0.03 * k);
    set.Values("fL")[k] = 1e3 * std::sin(0.03 * k);
  }
  return set;
}

TEST(MeasurementChannelsTest, SmoothDataWithAZeroClampDisplacementPass) {
  EXPECT_NO_THROW(CheckMeasurementChannels(SmoothSet(300), "smooth.csv"));
}

TEST(MeasurementChannelsTest, DeadChannelIsNamed) {
  ChannelSet set = SmoothSet(300);
  set.Values("f0").setZero();
  try {
    CheckMeasurementChannels(set, "dead.csv");
    ADD_FAILURE() << "no InputError thrown";
  } catch (const InputError& error) {
    EXPECT_EQ(std::string(error.what()),
              "dead.csv:2: column 'f0' is zero on every row: a dead channel (only u0, at the "
              "clamped end, may be zero)");
  }
}

TEST(MeasurementChannelsTest, OutlierIsNamedWithItsLine) {
  ChannelSet set = SmoothSet(300);
  set.Values("uL")[100] = 5e-6;  // five times the peak; sample 100 is on line 102
  try {
    CheckMeasurementChannels(set, "spike.csv");
    ADD_FAILURE() << "no InputError thrown";
  } catch (const InputError& error) {
    const std::string message = error.what();
    EXPECT_EQ(message.rfind("spike.csv:102: column 'uL': 5e-06 is an outlier", 0), 0u) << message;
  }
}

TEST(MeasurementChannelsTest, AnOutlierOnTheFirstOrLastSampleOrBesideItIsNamedAtItsLine) {
  // 300 samples on lines 2 to 301; uL's peak is 1e-6.
  for (const int sample : {0, 1, 298, 299}) {
    ChannelSet set = SmoothSet(300);
    set.Values("uL")[sample] = 5e-6;
    try {
      CheckMeasurementChannels(set, "spike.csv");
      ADD_FAILURE() << "no InputError thrown for sample " << sample;
    } catch (const InputError& error) {
      const std::string message = error.what();
      const std::string expected =
          "spike.csv:" + std::to_string(sample + 2) + ": column 'uL': 5e-06 is an outlier";
      EXPECT_EQ(message.rfind(expected, 0), 0u) << message;
    }
  }
}

TEST_F(MeasurementTest, MissingFile) {
  const std::string path = PathOf("absent.csv");
  try {
    ReadMeasurementCsv(path);
    ADD_FAILURE() << "no InputError thrown";
  } catch (const InputError& error) {
    EXPECT_EQ(std::string(error.what()),
              "cannot read measurement file " + path + ": No such file or directory");
  }
}

}  // namespace
}  // namespace mcrewave
