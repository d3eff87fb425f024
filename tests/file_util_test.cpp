// Tests of the atomic writers and gnuplot drawing (core/file_util.h).
#include "mcrewave/core/file_util.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <utility>
#include <vector>

#include "file_fixture.h"

namespace mcrewave {
namespace {

class GnuplotFiguresTest : public FileFixture {
 protected:
  GnuplotFiguresTest() : FileFixture("figures") {}

  // The folder's file names.
  std::vector<std::string> Files() const {
    std::vector<std::string> names;
    for (const auto& entry : std::filesystem::directory_iterator(PathOf(""))) {
      names.push_back(entry.path().filename().string());
    }
    return names;
  }
};

const std::string kGoodFigure = GnuplotPngTerminal() + "plot sin(x)\n";

// Every figure of one process drawn under its name, nothing else left in the folder.
TEST_F(GnuplotFiguresTest, OneProcessDrawsEveryFigure) {
  bool missing = false;
  const std::vector<std::string> why =
      DrawGnuplotFigures(PathOf(""), {{"first", kGoodFigure}, {"second", kGoodFigure}}, &missing);
  ASSERT_FALSE(missing) << "gnuplot is not on the PATH";
  ASSERT_EQ(why.size(), 2u);
  EXPECT_EQ(why[0], "");
  EXPECT_EQ(why[1], "");
  EXPECT_GT(std::filesystem::file_size(PathOf("first.png")), 0u);
  EXPECT_GT(std::filesystem::file_size(PathOf("second.png")), 0u);
  EXPECT_EQ(Files().size(), 2u);
}

// A failing figure fails the shared process: each is drawn again on its own, so the
// good ones are there and the bad one says why, without temporaries.
TEST_F(GnuplotFiguresTest, AFailingFigureLeavesTheOthersDrawn) {
  bool missing = false;
  const std::vector<std::string> why = DrawGnuplotFigures(
      PathOf(""),
      {{"good", kGoodFigure}, {"bad", "plot no_such_function(x)\n"}, {"after", kGoodFigure}},
      &missing);
  ASSERT_FALSE(missing) << "gnuplot is not on the PATH";
  ASSERT_EQ(why.size(), 3u);
  EXPECT_EQ(why[0], "");
  EXPECT_NE(why[1].find("gnuplot failed"), std::string::npos) << why[1];
  EXPECT_EQ(why[2], "");
  EXPECT_TRUE(std::filesystem::exists(PathOf("good.png")));
  EXPECT_FALSE(std::filesystem::exists(PathOf("bad.png")));
  EXPECT_TRUE(std::filesystem::exists(PathOf("after.png")));
  EXPECT_EQ(Files().size(), 2u);
}

// Settings of one figure do not reach the next (reset session between them): a figure
// drawn after another that set a log scale is the same bytes as drawn alone.
TEST_F(GnuplotFiguresTest, AFigureIsTheSameBytesAfterAnother) {
  bool missing = false;
  const std::string log_scale = GnuplotPngTerminal() + "set logscale y\nplot exp(x)\n";
  DrawGnuplotFigures(PathOf(""), {{"before", log_scale}, {"shared", kGoodFigure}}, &missing);
  ASSERT_FALSE(missing) << "gnuplot is not on the PATH";
  ASSERT_EQ(DrawGnuplotFigure(PathOf(""), "alone", kGoodFigure, &missing), "");
  std::ifstream shared(PathOf("shared.png"), std::ios::binary);
  std::ifstream alone(PathOf("alone.png"), std::ios::binary);
  const std::string shared_bytes((std::istreambuf_iterator<char>(shared)),
                                 std::istreambuf_iterator<char>());
  const std::string alone_bytes((std::istreambuf_iterator<char>(alone)),
                                std::istreambuf_iterator<char>());
  EXPECT_FALSE(alone_bytes.empty());
  EXPECT_TRUE(shared_bytes == alone_bytes);
}

}  // namespace
}  // namespace mcrewave
