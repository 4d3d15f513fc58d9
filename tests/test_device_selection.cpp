// RendererOptions::device: a device by index, by name, and by UUID (what a cluster scheduler hands a
// task on a shared node, since Vulkan ignores CUDA_VISIBLE_DEVICES); --list-devices prints the UUIDs.
#include <gtest/gtest.h>

#include <algorithm>
#include <cctype>
#include <regex>
#include <stdexcept>
#include <string>
#include <vector>

#include "process_support.h"
#include "tilesplat/renderer.h"

namespace {

std::string upper(std::string text) {
  std::transform(text.begin(), text.end(), text.begin(),
                 [](unsigned char c) { return char(std::toupper(c)); });
  return text;
}

TEST(DeviceSelection, EveryDeviceHasAUuidAndIsFoundByIt) {
  const std::vector<std::string> names = tilesplat::list_devices();
  const std::vector<std::string> uuids = tilesplat::list_device_uuids();
  ASSERT_FALSE(names.empty());
  ASSERT_EQ(uuids.size(), names.size());
  const std::regex form("[0-9a-f]{8}-[0-9a-f]{4}-[0-9a-f]{4}-[0-9a-f]{4}-[0-9a-f]{12}");
  for (size_t i = 0; i < uuids.size(); ++i) {
    EXPECT_TRUE(std::regex_match(uuids[i], form)) << uuids[i];
    std::string no_dashes = uuids[i];
    no_dashes.erase(std::remove(no_dashes.begin(), no_dashes.end(), '-'), no_dashes.end());
    // As listed, as nvidia-smi prints it ("GPU-" and upper case), and as 32 bare digits.
    for (const std::string& selector : {uuids[i], "GPU-" + upper(uuids[i]), no_dashes}) {
      tilesplat::RendererOptions options;
      options.device = selector;
      const auto renderer = tilesplat::Renderer::create(options);
      EXPECT_EQ(renderer->device_info().name, names[i]) << selector;
    }
  }
}

TEST(DeviceSelection, AnUnknownUuidIsAnErrorListingTheDevicesAndTheirUuids) {
  tilesplat::RendererOptions options;
  options.device = "GPU-00000000-1111-2222-3333-444444444444";
  try {
    tilesplat::Renderer::create(options);
    FAIL() << "no exception";
  } catch (const std::runtime_error& error) {
    const std::string message = error.what();
    EXPECT_NE(message.find("no Vulkan device matches 'GPU-00000000-1111-2222-3333-444444444444'"),
              std::string::npos)
        << message;
    EXPECT_NE(message.find(tilesplat::list_device_uuids().front()), std::string::npos) << message;
  }
}

TEST(DeviceSelection, ListDevicesFlagPrintsTheUuids) {
  const auto result = tilesplat::testing::run_process("", TILESPLAT_RENDER_EXE, {"--list-devices"});
  ASSERT_EQ(result.exit_code, 0) << result.err;
  EXPECT_NE(result.out.find("0: " + tilesplat::list_devices().front() + " (uuid " +
                            tilesplat::list_device_uuids().front() + ")"),
            std::string::npos)
      << result.out;
}

}  // namespace
