// libFuzzer harness for scene files (docs/scene-format.md): the input is the JSON of a scene file in a
// folder that holds one splat file, m.ply, for "models" to name (the parser checks that a model exists;
// it does not read it). Every input must parse into a description whose cameras, lenses and lights a
// renderer accepts (and shutters and motions too), or throw a SceneError that names the file; see
// tests/fuzz/README.md.
#include <unistd.h>

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>
#include <string_view>

#include "fuzz_checks.h"
#include "tilesplat/lens.h"
#include "tilesplat/scene_description.h"

namespace {

namespace fs = std::filesystem;

// A folder of this process's own (libFuzzer may run several processes side by side), with m.ply in it.
const fs::path& work_folder() {
  static const fs::path folder = [] {
    const fs::path path =
        fs::temp_directory_path() / ("tilesplat_fuzz_scene_file_" + std::to_string(::getpid()));
    fs::create_directories(path);
    std::ofstream(path / "m.ply") << "ply\n";
    return path;
  }();
  return folder;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const fs::path file = work_folder() / "scene.json";
  try {
    const tilesplat::SceneDescription description =
        tilesplat::parse_scene_description(std::string_view(reinterpret_cast<const char*>(data), size), file);
    FUZZ_CHECK(!description.models.empty());
    FUZZ_CHECK(description.lenses.empty() || description.lenses.size() == description.cameras.size());
    for (const tilesplat::CameraView& view : description.cameras) {
      tilesplat::validate(view.camera);  // throws std::invalid_argument, which libFuzzer reports
      // Its lens model's limits end and a point ahead projects to finite numbers or not at all.
      if (const auto pixel = view.camera.project({0.1, -0.05, 2.0}))
        FUZZ_CHECK(std::isfinite((*pixel)[0]) && std::isfinite((*pixel)[1]));
    }
    for (const tilesplat::ThinLens& lens : description.lenses) tilesplat::validate(lens);
    FUZZ_CHECK(description.shutters.size() == description.lenses.size());
    for (size_t i = 0; i < description.shutters.size(); ++i) {
      const tilesplat::Shutter& shutter = description.shutters[i];
      FUZZ_CHECK(shutter.opens() || shutter == tilesplat::Shutter{});
      if (shutter.end_camera) {  // the same camera, moved
        tilesplat::validate(shutter);
        FUZZ_CHECK(shutter.end_camera->width == description.cameras[i].camera.width);
      }
    }
    // A moving model's path is valid all the way (throws std::invalid_argument otherwise).
    for (const tilesplat::SceneModel& model : description.models)
      if (model.motion) tilesplat::transform_between(model.transform, *model.motion, 0.5);
  } catch (const tilesplat::SceneError& error) {
    FUZZ_CHECK(std::string(error.what()).starts_with(file.string()));
  }
  return 0;
}
