// The front ends' one computation (app/run.h): a model and a record given in code take
// the steps of the files the config names, to the bit, and are refused as they are; a
// stop requested (core/interrupt.h) ends an identification under way as a failure
// that says so.
#include "mcrewave/app/run.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "identify_binary.h"
#include "mcrewave/app/config.h"
#include "mcrewave/core/interrupt.h"
#include "mcrewave/data/measurement.h"
#include "mcrewave/model/matrix_export.h"

namespace mcrewave {
namespace {

using testing::FreshDirectory;
using testing::SourcePath;

// configs/quick.yaml on its bar exported as matrices (written into `folder`), the
// zone's nominal modulus 160 GPa, its data the truth's at 210 GPa.
Config QuickBarAsMatrices(const std::string& folder) {
  Config config = LoadConfig(SourcePath("configs/quick.yaml"));
  std::filesystem::create_directories(folder);
  config.structure.kind = ModelKind::kMatrix;
  config.structure.manifest =
      WriteMatrixModel(folder, BarMatrixModel(BarModel(config.model), 160e9));
  config.data.truth_moduli = {210e9};
  return config;
}

TEST(RunTest, AModelAndARecordGivenInCodeAreIdentifiedAsTheConfigsFiles) {
  const std::string folder = FreshDirectory("run_given_matrices");
  const Config config = QuickBarAsMatrices(folder);
  const IdentificationRun from_files = IdentifyFromConfig(config);
  ASSERT_TRUE(from_files.IsUsable()) << from_files.failure;

  // The model given in code, and the data as `identify simulate` writes them given in
  // code (taken as a CSV's, the synthetic keys unread): the same moduli and e^2, bit
  // for bit.
  const MatrixModelData model = ReadMatrixModel(config.structure.manifest);
  const ChannelSet record = SimulatedMeasurements(config);
  GivenInputs given;
  given.model = &model;
  given.record = &record;
  given.record_name = "the simulated record";
  const IdentificationRun from_code = IdentifyFromConfig(config, given);
  EXPECT_EQ(from_code.config.data.source, DataSource::kCsv);
  EXPECT_FALSE(from_code.reference_known);
  ASSERT_TRUE(from_code.IsUsable()) << from_code.failure;
  EXPECT_EQ(from_code.identified_moduli[0], from_files.identified_moduli[0]);
  EXPECT_EQ(from_code.zone_cost, from_files.zone_cost);
  EXPECT_EQ(from_code.data_source, "the simulated record");
  // The truth is the model itself at 210 GPa, SNR 20, the paper's free-free formulation
  // of quick.yaml: measured -2.9 %.
  EXPECT_NEAR(from_code.identified_moduli[0] / 210e9, 1.0, 0.06);

  // The model given in code is the synthetic truth when data.truth_manifest is empty.
  GivenInputs model_only;
  model_only.model = &model;
  const IdentificationRun synthetic = IdentifyFromConfig(config, model_only);
  ASSERT_TRUE(synthetic.IsUsable()) << synthetic.failure;
  EXPECT_EQ(synthetic.identified_moduli[0], from_files.identified_moduli[0]);
}

TEST(RunTest, TheBarsRecordGivenInCodeIsItsCsvs) {
  const std::string folder = FreshDirectory("run_given_bar_record");
  Config config = LoadConfig(SourcePath("configs/quick.yaml"));
  const ChannelSet record = SimulatedMeasurements(config);
  WriteMeasurementCsv(record, folder + "/data.csv");
  config.data.source = DataSource::kCsv;
  config.data.path = folder + "/data.csv";
  const IdentificationRun from_csv = IdentifyFromConfig(config);
  ASSERT_TRUE(from_csv.IsUsable()) << from_csv.outer.message;

  // The record's kinds are not trusted: they come from the names, as a CSV's do.
  ChannelSet unkinded = record;
  for (Channel& channel : unkinded.channels) channel.kind = ChannelKind::kDisplacement;
  GivenInputs given;
  given.record = &unkinded;
  given.record_name = "the record";
  const IdentificationRun from_code = IdentifyFromConfig(config, given);
  ASSERT_TRUE(from_code.IsUsable()) << from_code.outer.message;
  EXPECT_EQ(from_code.identified_modulus(), from_csv.identified_modulus());
  EXPECT_EQ(from_code.cost(), from_csv.cost());
}

TEST(RunTest, ARecordGivenInCodeIsRefusedAsACsvIs) {
  const std::string folder = FreshDirectory("run_given_bad_record");
  Config bar = LoadConfig(SourcePath("configs/quick.yaml"));
  ChannelSet record = SimulatedMeasurements(bar);
  record.channels.erase(record.channels.begin() + record.Find("f0"));
  GivenInputs given;
  given.record = &record;
  given.record_name = "my record";
  try {
    IdentifyFromConfig(bar, given);
    ADD_FAILURE() << "a record without f0 was accepted";
  } catch (const InputError& error) {
    EXPECT_EQ(std::string(error.what())
                  .rfind("my record: the header 't,u0,uL,fL' lacks the "
                         "column 'f0'",
                         0),
              0u)
        << error.what();
  }

  const Config matrices = QuickBarAsMatrices(folder);
  ChannelSet table = SimulatedMeasurements(matrices);
  table.channels.erase(table.channels.begin() + table.Find("fL"));
  given.record = &table;
  try {
    IdentifyFromConfig(matrices, given);
    ADD_FAILURE() << "a record without fL was accepted";
  } catch (const InputError& error) {
    EXPECT_EQ(std::string(error.what()),
              "my record: the record lacks the column 'fL' of the model's channel 'fL' "
              "(model.channel_map can name another column)");
  }
}

TEST(RunTest, AModelGivenInCodeNeedsTheMatrixKind) {
  const Config bar = LoadConfig(SourcePath("configs/quick.yaml"));
  const MatrixModelData model = BarMatrixModel(BarModel(bar.model), 160e9);
  GivenInputs given;
  given.model = &model;
  for (const bool simulate : {false, true}) {
    try {
      if (simulate) {
        SimulatedMeasurements(bar, given);
      } else {
        IdentifyFromConfig(bar, given);
      }
      ADD_FAILURE() << "a model given with model.kind bar was accepted";
    } catch (const InputError& error) {
      EXPECT_NE(std::string(error.what()).find("a model given in code needs model.kind: matrix"),
                std::string::npos)
          << error.what();
    }
  }
}

// zone_identification.start_modulus: the zones start there, without the homogeneous
// stage, by the MCRE and by least squares, and reach the minimum the homogeneous start
// reaches.
TEST(RunTest, AStartModulusSkipsTheHomogeneousStage) {
  const std::string folder = FreshDirectory("run_start_modulus");
  for (const OuterFunctional functional :
       {OuterFunctional::kMcre, OuterFunctional::kLeastSquares}) {
    Config config = QuickBarAsMatrices(folder);
    config.outer.functional = functional;
    const IdentificationRun homogeneous = IdentifyFromConfig(config);
    ASSERT_TRUE(homogeneous.IsUsable()) << homogeneous.failure;
    EXPECT_TRUE(homogeneous.homogeneous_ran);
    config.zone_identification.start_modulus = 1.2e11;
    ASSERT_EQ(ConfigProblem(config), "");
    const IdentificationRun started = IdentifyFromConfig(config);
    ASSERT_TRUE(started.IsUsable()) << started.failure;
    EXPECT_FALSE(started.homogeneous_ran);
    EXPECT_EQ(started.zones.summary.start_moduli[0], 1.2e11);
    // The same minimum from 43 % below it: measured 2.3e-8 apart (MCRE) and 4.5e-9 (least
    // squares), each optimiser's tolerance.
    EXPECT_NEAR(started.identified_moduli[0] / homogeneous.identified_moduli[0], 1.0, 2e-7)
        << OuterFunctionalToString(functional);
  }
}

// zone_identification.start_moduli: one start per zone takes the path of start_modulus
// (the same bits with equal starts); a list of the wrong length is refused naming the
// key before any solve. uncertainty.samples 0 leaves the moduli's bits as they are and
// says why no uncertainty is given.
TEST(RunTest, StartModuliPerZoneAndNoUncertainty) {
  const std::string folder = FreshDirectory("run_start_moduli");
  Config config = QuickBarAsMatrices(folder);
  config.zone_identification.start_modulus = 1.2e11;
  const IdentificationRun one_for_all = IdentifyFromConfig(config);
  ASSERT_TRUE(one_for_all.IsUsable()) << one_for_all.failure;
  ASSERT_TRUE(one_for_all.zone_uncertainty.available) << one_for_all.zone_uncertainty.message;

  config.zone_identification.start_modulus = 0.0;
  config.zone_identification.start_moduli = {1.2e11};
  config.uncertainty.samples = 0;
  ASSERT_EQ(ConfigProblem(config), "");
  const IdentificationRun per_zone = IdentifyFromConfig(config);
  ASSERT_TRUE(per_zone.IsUsable()) << per_zone.failure;
  EXPECT_FALSE(per_zone.homogeneous_ran);
  EXPECT_EQ(per_zone.zones.summary.start_moduli[0], 1.2e11);
  EXPECT_EQ(per_zone.identified_moduli[0], one_for_all.identified_moduli[0]);
  EXPECT_EQ(per_zone.zones.summary.evaluations, one_for_all.zones.summary.evaluations);
  EXPECT_FALSE(per_zone.zone_uncertainty.available);
  EXPECT_EQ(per_zone.zone_uncertainty.message, kUncertaintyOffMessage);
  EXPECT_EQ(per_zone.zone_uncertainty.sweeps, 0);

  config.zone_identification.start_moduli = {1.2e11, 1.3e11};
  try {
    IdentifyFromConfig(config);
    ADD_FAILURE() << "two start moduli for one zone were taken";
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what())
                  .find("zone_identification.start_moduli has 2 moduli, the model has 1 zones"),
              std::string::npos)
        << error.what();
  }
}

TEST(RunTest, AStopRequestedEndsTheIdentificationAsAFailureThatSaysSo) {
  const Config config = LoadConfig(SourcePath("configs/quick.yaml"));
  RequestInterrupt();
  const IdentificationRun stopped = IdentifyFromConfig(config);
  ClearInterrupt();
  EXPECT_FALSE(stopped.IsUsable());
  EXPECT_NE(UnreportableMessage(stopped).find(kInterruptedMessage), std::string::npos)
      << UnreportableMessage(stopped);
  // Cleared, the same run converges.
  EXPECT_TRUE(IdentifyFromConfig(config).IsUsable());
}

}  // namespace
}  // namespace mcrewave
