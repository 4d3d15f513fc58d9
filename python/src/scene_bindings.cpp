// Scenes for Python: tilesplat.Scene (the arrays as numpy views of the scene's own memory), load_scene,
// a scene file's placed copies (SceneInstances), a file read part by part (SceneInParts) and LOD sets.
#include <nanobind/nanobind.h>
#include <nanobind/stl/array.h>
#include <nanobind/stl/filesystem.h>
#include <nanobind/stl/optional.h>
#include <nanobind/stl/string.h>
#include <nanobind/stl/vector.h>

#include <string>
#include <vector>

#include "bindings.h"
#include "tilesplat/lod_set.h"
#include "tilesplat/scene.h"
#include "tilesplat/scene_description.h"
#include "tilesplat/scene_in_parts.h"

namespace tilesplat::python {

using namespace nb::literals;

namespace {

// tilesplat.Scene and load_scene.
void bind_gaussian_scene(nb::module_& m) {
  nb::class_<GaussianScene>(
      m, "Scene",
      "N Gaussians as the trainer stores them (log scales, opacity logits, SH), structure "
      "of arrays; the arrays are numpy views of the scene's own memory.")
      .def_prop_ro("size", &GaussianScene::size, "N, the number of Gaussians")
      .def_prop_ro(
          "sh_degree", [](const GaussianScene& s) { return s.sh_degree; }, "0..3")
      .def_prop_ro(
          "positions",
          [](nb::handle self) {
            auto& s = nb::cast<GaussianScene&>(self);
            return view_of(s.positions, {s.size(), 3}, self);
          },
          "(N, 3) world-space means")
      .def_prop_ro(
          "log_scales",
          [](nb::handle self) {
            auto& s = nb::cast<GaussianScene&>(self);
            return view_of(s.log_scales, {s.size(), 3}, self);
          },
          "(N, 3) log of the scales")
      .def_prop_ro(
          "rotations",
          [](nb::handle self) {
            auto& s = nb::cast<GaussianScene&>(self);
            return view_of(s.rotations, {s.size(), 4}, self);
          },
          "(N, 4) unit quaternions w x y z")
      .def_prop_ro(
          "opacity_logits",
          [](nb::handle self) {
            auto& s = nb::cast<GaussianScene&>(self);
            return view_of(s.opacity_logits, {s.size()}, self);
          },
          "(N,) logits of the opacities")
      .def_prop_ro(
          "sh",
          [](nb::handle self) {
            auto& s = nb::cast<GaussianScene&>(self);
            return view_of(s.sh, {s.size(), size_t(s.sh_coefficients()), 3}, self);
          },
          "(N, K, 3) SH coefficients, K = (sh_degree + 1)^2; k = 0 is the DC term")
      .def_static(
          "from_arrays",
          [](const FloatInput& positions, const FloatInput& log_scales, const FloatInput& rotations,
             const FloatInput& opacity_logits, const FloatInput& sh) {
            GaussianScene scene;
            scene.positions = finite_values(positions, "positions", {-1, 3});
            const size_t n = scene.positions.size() / 3;
            scene.log_scales = finite_values(log_scales, "log_scales", {int64_t(n), 3});
            scene.rotations = finite_values(rotations, "rotations", {int64_t(n), 4});
            scene.opacity_logits = finite_values(opacity_logits, "opacity_logits", {int64_t(n)});
            scene.sh = finite_values(sh, "sh", {int64_t(n), -1, 3});
            const size_t k = sh.ndim() == 3 ? sh.shape(1) : 0;
            int degree = 0;
            while (degree <= 3 && size_t((degree + 1) * (degree + 1)) != k) ++degree;
            if (degree > 3)
              throw std::invalid_argument("sh must have 1, 4, 9 or 16 coefficients, got " +
                                          std::to_string(k));
            scene.sh_degree = degree;
            return scene;
          },
          "positions"_a, "log_scales"_a, "rotations"_a, "opacity_logits"_a, "sh"_a,
          "A scene from arrays: positions (N, 3), log_scales (N, 3), rotations (N, 4) w x y z, "
          "opacity_logits "
          "(N,), sh (N, K, 3) with K = 1, 4, 9 or 16. Values are copied as given (a quaternion of any "
          "length: the "
          "renderer normalizes it, and a zero one is the identity); non-finite ones raise ValueError.")
      .def(
          "write_ply",
          [](const GaussianScene& scene, const std::filesystem::path& path) {
            nb::gil_scoped_release release;
            write_ply(scene, path);
          },
          "path"_a,
          "Writes the scene as the 3DGS trainer's binary PLY (x y z, f_dc, f_rest, opacity, scale, rot; nx "
          "ny nz "
          "when it has normals), which every viewer reads; load_scene gives each value back to the bit (the "
          "quaternions normalized again, as every reader does). Atomic: "
          "no partial file. ValueError for inconsistent arrays, RuntimeError naming the file when it cannot "
          "be "
          "written.")
      .def("__repr__", [](const GaussianScene& s) {
        return "<tilesplat.Scene " + std::to_string(s.size()) + " Gaussians, SH degree " +
               std::to_string(s.sh_degree) + ">";
      });

  m.def(
      "load_scene",
      [](const std::filesystem::path& path, bool strict) {
        check_exists(path, "scene");
        LoadOptions options;
        options.strict = strict;
        nb::gil_scoped_release release;
        if (is_scene_description(path)) return load_described_scene(load_scene_description(path), options);
        return load_scene(path, options);
      },
      "path"_a, "strict"_a = false,
      "Loads a scene: a splat file of any format the library reads (.ply, .compressed.ply, .splat, .spz, "
      ".sog, "
      "SOG meta.json, .glb, .gltf) or a scene file (.json). strict: fail on a non-finite value instead of "
      "dropping the Gaussian.");
}

// A scene file's models as placed copies, some of which may move (SceneInstances), and a file read
// part by part (SceneInParts).
void bind_scene_sources(nb::module_& m) {
  nb::class_<SceneInstances>(
      m, "SceneInstances",
      "A scene file's models as placed copies of their files (each file held once), where some may move "
      "(a model's \"motion\"): Renderer.render(camera, instances=..., shutter=...) blurs them while the "
      "shutter is open (docs/effects.md, \"Moving models\").")
      .def(
          "__init__",
          [](SceneInstances* self, const std::filesystem::path& path, bool strict) {
            check_exists(path, "scene file");
            LoadOptions options;
            options.strict = strict;
            nb::gil_scoped_release release;
            new (self) SceneInstances(load_scene_instances(load_scene_description(path), options));
          },
          "path"_a, "strict"_a = false, "Reads a scene file (.json) and the splat files it names.")
      .def_prop_ro("size", &SceneInstances::size, "the Gaussians of the merged scene")
      .def_prop_ro("moves", &SceneInstances::moves, "whether any model moves")
      .def(
          "scene_at",
          [](const SceneInstances& scene, double t) {
            nb::gil_scoped_release release;
            return merge_instances(scene, t);
          },
          "t"_a = 0.0, "The merged scene with every model where it is at time t in [0, 1].");

  // --- a binary PLY, an SPZ or a SOG read part by part
  nb::class_<SceneInParts>(
      m, "SceneInParts",
      "A binary PLY, an SPZ or a SOG opened to be read part by part: the Gaussians' positions are held (and "
      "an SPZ's packed bytes or a SOG's texels), and Renderer.render(camera, in_parts=..., "
      "memory_budget=...) decodes each "
      "part as it is drawn, the frame of load_scene's scene to the bit (docs/big-scenes.md, \"Read part by "
      "part\"). MappedPly is its earlier name.")
      .def(
          "__init__",
          [](SceneInParts* self, const std::filesystem::path& path, bool strict) {
            check_exists(path, "scene");
            LoadOptions options;
            options.strict = strict;
            nb::gil_scoped_release release;
            new (self) SceneInParts(SceneInParts::open(path, options));
          },
          "path"_a, "strict"_a = false,
          "Opens a binary PLY, an SPZ or a SOG (an ASCII or a compressed PLY and the other formats are "
          "refused: "
          "load_scene reads those whole).")
      .def_prop_ro("size", &SceneInParts::size, "the Gaussians")
      .def_prop_ro("sh_degree", &SceneInParts::sh_degree, "0 to 3")
      .def_static("whole_scene_bytes", &SceneInParts::whole_scene_bytes, "path"_a,
                  "The bytes load_scene's arrays would take for the file, from its header alone (0 for a "
                  "file SceneInParts does not open).")
      .def(
          "load",
          [](const SceneInParts& scene) {
            nb::gil_scoped_release release;
            return scene.load();
          },
          "The whole scene, as load_scene reads it.")
      .def("__repr__", [](const SceneInParts& scene) {
        return "<tilesplat.SceneInParts " + std::to_string(scene.size()) + " Gaussians (SH" +
               std::to_string(scene.sh_degree()) + ")>";
      });
  m.attr("MappedPly") = m.attr("SceneInParts");
}

// Level-of-detail sets (LodSet) and what they select for a camera (LodSelection).
void bind_lod_sets(nb::module_& m) {
  nb::class_<LodSelection>(m, "LodSelection", "The level each chunk of a LOD set is drawn at for one camera.")
      .def_ro("chunk_levels", &LodSelection::chunk_levels, "per chunk: the level drawn, or -1 out of view")
      .def_ro("splats", &LodSelection::splats, "Gaussians drawn")
      .def_ro("coarsest_splats", &LodSelection::coarsest_splats,
              "what the chunks in view cost at their coarsest")
      .def_ro("over_budget", &LodSelection::over_budget, "the budget was below coarsest_splats")
      .def("__repr__", [](const LodSelection& s) {
        return "<tilesplat.LodSelection " + std::to_string(s.splats) + " splats of " +
               std::to_string(s.chunk_levels.size()) + " chunks>";
      });
  nb::class_<LodSet>(
      m, "LodSet",
      "A level-of-detail set: splat-transform's lod-meta.json, a scene in spatial chunks held at "
      "several levels (0 the finest). docs/big-scenes.md.")
      .def(
          "__init__",
          [](LodSet* self, const std::filesystem::path& path) {
            check_exists(path, "LOD set index");
            new (self) LodSet(LodSet::open(path));
          },
          "path"_a, "Reads and checks the index (the chunk files are read when a level needs them).")
      .def_prop_ro("levels", &LodSet::levels, "the number of levels")
      .def_prop_ro(
          "chunks", [](const LodSet& set) { return set.chunks().size(); }, "the number of chunks")
      .def("level_size", &LodSet::level_size, "level"_a, "Gaussians at a level")
      .def(
          "chunk_sizes",
          [](const LodSet& set, int level) {
            set.level_size(level);  // raises for a level the set does not have
            std::vector<uint64_t> sizes;
            for (const LodChunk& chunk : set.chunks()) sizes.push_back(chunk.levels[size_t(level)].count);
            return sizes;
          },
          "level"_a,
          "Gaussians of each chunk at a level, in the order load_level and load_selection put them")
      .def(
          "load_level",
          [](const LodSet& set, int level) {
            nb::gil_scoped_release release;
            return set.load_level(level);
          },
          "level"_a, "The scene that level draws: every chunk at it, then the environment.")
      .def(
          "select",
          [](const LodSet& set, const Camera& camera, uint64_t splat_budget) {
            return select_lod_levels(set, camera, splat_budget);
          },
          "camera"_a, "splat_budget"_a,
          "The levels the camera calls for under the budget: chunks out of view left out, the rest refined "
          "from their coarsest level where their Gaussians cover the most pixels each.")
      .def(
          "load_selection",
          [](const LodSet& set, const LodSelection& selection) {
            nb::gil_scoped_release release;
            return set.load_selection(selection);
          },
          "selection"_a, "The chunks at the levels a selection chose, then the environment.")
      .def("__repr__", [](const LodSet& set) {
        std::string counts;
        for (int level = 0; level < set.levels(); ++level)
          counts += (level ? " / " : "") + std::to_string(set.level_size(level));
        return "<tilesplat.LodSet " + std::to_string(set.levels()) + " levels (" + counts + " Gaussians)>";
      });
}

}  // namespace

void bind_scenes(nb::module_& m) {
  bind_gaussian_scene(m);
  bind_scene_sources(m);
  bind_lod_sets(m);
}

}  // namespace tilesplat::python
