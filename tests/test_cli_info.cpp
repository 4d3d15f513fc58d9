// tilesplat-info as a user runs it: the text and JSON summaries of files in every format, and the
// errors of missing files and bad flags (one line each, a non-zero exit, the other files still shown).
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include <string>

#include "process_support.h"
#include "test_support.h"

namespace tilesplat {
namespace {

using testing::run_process;

TEST(CliInfo, SummarizesFilesOfEveryFormat) {
  TILESPLAT_REQUIRE_SHARED_SCENES();
  const auto formats = testing::shared_scenes() / "formats";
  const std::vector<std::string> files = {(formats / "playcanvas_test_64_sh3.v4.spz").string(),
                                          (formats / "playcanvas_test_64_sh3.sog").string(),
                                          (formats / "playcanvas_test_64_sh3.glb").string(),
                                          (formats / "playcanvas_test_64_sh3.compressed.ply").string(),
                                          (testing::shared_scenes() / "train_3pts.splat").string()};
  std::vector<std::string> args = {"--json"};
  args.insert(args.end(), files.begin(), files.end());
  const auto result = run_process("", TILESPLAT_INFO_EXE, args);
  ASSERT_EQ(result.exit_code, 0) << result.err;
  const nlohmann::json all = nlohmann::json::parse(result.out);
  ASSERT_EQ(all.size(), files.size());
  const std::string expected_formats[] = {"spz", "sog", "glb", "compressed ply", "splat"};
  for (size_t i = 0; i < files.size(); ++i) {
    const nlohmann::json& info = all[i];
    EXPECT_EQ(info["format"], expected_formats[i]) << files[i];
    EXPECT_EQ(info["gaussians"], i == 4 ? 3 : 64) << files[i];
    EXPECT_EQ(info["sh_degree"], i == 4 ? 0 : 3) << files[i];
    EXPECT_GT(info["file_bytes"].get<double>(), 0) << files[i];
    EXPECT_GT(info["load_ms"].get<double>(), 0) << files[i];
    EXPECT_LE(info["box_min"][0].get<double>(), info["robust_box_min"][0].get<double>()) << files[i];
    EXPECT_GE(info["box_max"][0].get<double>(), info["robust_box_max"][0].get<double>()) << files[i];
    EXPECT_GT(info["opacity_range"][0].get<double>(), 0) << files[i];
    EXPECT_LE(info["opacity_range"][1].get<double>(), 1) << files[i];
  }
  EXPECT_EQ(all[0]["version"], "4");

  const auto text = run_process("", TILESPLAT_INFO_EXE, {files[0]});
  ASSERT_EQ(text.exit_code, 0) << text.err;
  for (const char* field : {"format       spz version 4", "64 Gaussians (SH3)", "bytes per Gaussian",
                            "1-99% box", "opacity", "scale", "non-finite   0 of 64", "peak memory"})
    EXPECT_NE(text.out.find(field), std::string::npos) << field << " in\n" << text.out;
}

TEST(CliInfo, BadFilesAndFlags) {
  TILESPLAT_REQUIRE_SHARED_SCENES();
  const std::string good = (testing::shared_scenes() / "train_3pts.spz").string();
  const std::string absent = (testing::temp_dir() / "no_such_file.spz").string();
  const auto missing = run_process("", TILESPLAT_INFO_EXE, {absent, good});
  EXPECT_EQ(missing.exit_code, 1);
  testing::expect_one_error_line(missing, "tilesplat-info");
  EXPECT_NE(missing.err.find(absent), std::string::npos) << missing.err;
  EXPECT_NE(missing.out.find("train_3pts.spz"), std::string::npos) << "the good file is still shown";
  const auto none = run_process("", TILESPLAT_INFO_EXE, {});
  EXPECT_EQ(none.exit_code, 2);
  testing::expect_one_error_line(none, "tilesplat-info");
  const auto flag = run_process("", TILESPLAT_INFO_EXE, {"--no-such-flag", good});
  EXPECT_EQ(flag.exit_code, 2);
  testing::expect_one_error_line(flag, "tilesplat-info");
}

}  // namespace
}  // namespace tilesplat
