// The compressed and interchange formats (.splat, .spz, SOG, compressed PLY, glTF) against the PLYs
// beside them in ../shared/scenes: the same Gaussians, the same images; and every malformed file
// refused with one clear error that names it.
#include <gtest/gtest.h>
#include <zip.h>
#include <zlib.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "process_support.h"
#include "test_support.h"
#include "tilesplat/camera.h"
#include "tilesplat/image.h"
#include "tilesplat/renderer.h"
#include "tilesplat/scene.h"
#include "tilesplat/scene_in_parts.h"

namespace tilesplat {
namespace {

namespace fs = std::filesystem;

// How close a native file's Gaussians must be to the PLY beside it.
struct Tolerance {
  // Both sides are float32 roundings of the same double expression (the reader's and the reference
  // decoder's), so they agree to an ulp or two: 1e-6 relative (1e-6 absolute below 1) for positions,
  // log scales and SH. Rotations are compared normalized and up to sign (q and -q are one rotation).
  // Opacity is compared after the sigmoid: decoders clamp 8-bit 0 and 255 to 1e-6 from 0 and 1 with
  // slightly different epsilons, and a glTF stores sigmoid(logit) as float, where logits past ~16
  // all round to 1.0, so only the activated value can be recovered.
  double position = 1e-6, log_scale = 1e-6, rotation = 1e-6, opacity = 2e-6, sh_dc = 1e-6, sh_rest = 1e-6;
};

// train_3pts.splat/.spz sit beside the raw trainer output they were written from, not a decoding:
// the bound is the formats' quantization step. 12 fractional bits of position (half a step 1.2e-4),
// log scales in 1/16 (half 0.031), 8-bit opacity (a full step 3.9e-3: writers truncate or round), 8-bit
// colours over SPZ's 0.15 colour scale (1/255/0.15/2 = 0.013), SH in buckets of 1/8 for degree 1 and 2+ in
// SPZ v3 (0.0625) plus float noise.
constexpr Tolerance kQuantized{2e-4, 0.035, 0.01, 4e-3, 0.014, 0.07};

struct FormatCase {
  std::string native;    // relative to the shared scenes
  std::string decoded;   // the PLY it is checked against
  std::string cameras;   // cameras/NAME.json
  bool decoding = true;  // false: `decoded` is the quantized file's source, not its decoding
};

std::vector<FormatCase> format_cases() {
  std::vector<FormatCase> cases;
  for (const std::string name : {"playbot_lod6_1873_sh2", "playcanvas_test_64_sh3"}) {
    for (const std::string extension : {"v4.spz", "v3.spz", "compressed.ply", "sog"})
      cases.push_back(
          {"formats/" + name + "." + extension, "formats/decoded/" + name + "." + extension + ".ply", name});
    // splat-transform does not read glTF: its source PLY is the reference (its values are float32 copies).
    cases.push_back({"formats/" + name + ".glb", name + ".ply", name});
  }
  cases.push_back({"formats/playbot_lod6_1873_sh2_sog_unbundled/meta.json",
                   "formats/decoded/playbot_lod6_1873_sh2_sog_unbundled.ply", "playbot_lod6_1873_sh2"});
  cases.push_back({"biker_152746.spz", "biker_152746_sh0.ply", "biker_152746_sh0"});
  cases.push_back({"guitar_90854.compressed.ply", "guitar_90854_sh0.ply", "guitar_90854_sh0"});
  cases.push_back({"plant_113648.splat", "plant_113648_sh0.ply", "plant_113648_sh0"});
  cases.push_back({"playbot_lod6_1873.sog", "playbot_lod6_1873_sh2.ply", "playbot_lod6_1873_sh2"});
  cases.push_back({"playbot_lod0_500000.sog", "playbot_lod0_500000_sh2.ply", "playbot_lod0_500000_sh2"});
  cases.push_back(
      {"playcanvas_test_64.compressed.ply", "playcanvas_test_64_sh3.ply", "playcanvas_test_64_sh3"});
  cases.push_back({"train_3pts.splat", "train_3pts_sh3.ply", "train_3pts_sh3", false});
  cases.push_back({"train_3pts.spz", "train_3pts_sh3.ply", "train_3pts_sh3", false});
  return cases;
}

double sigmoid(double x) {
  return 1.0 / (1.0 + std::exp(-x));
}

// The largest violation of `tolerance`, as a fraction of it (<= 1 passes), per attribute.
void expect_same_gaussians(const GaussianScene& native, const GaussianScene& decoded,
                           const Tolerance& tolerance) {
  ASSERT_EQ(native.size(), decoded.size());
  const size_t n = native.size();
  const auto close = [](double a, double b, double bound) {
    return std::fabs(a - b) <= bound * std::max(1.0, std::fabs(b));
  };
  size_t bad_position = 0, bad_scale = 0, bad_rotation = 0, bad_opacity = 0, bad_dc = 0, bad_rest = 0;
  const size_t k_native = static_cast<size_t>(native.sh_coefficients());
  const size_t k_decoded = static_cast<size_t>(decoded.sh_coefficients());
  for (size_t i = 0; i < n; ++i) {
    for (size_t a = 0; a < 3; ++a) {
      bad_position += !close(native.positions[3 * i + a], decoded.positions[3 * i + a], tolerance.position);
      bad_scale += !close(native.log_scales[3 * i + a], decoded.log_scales[3 * i + a], tolerance.log_scale);
    }
    double dot = 0;
    for (size_t j = 0; j < 4; ++j) dot += double(native.rotations[4 * i + j]) * decoded.rotations[4 * i + j];
    const double sign = dot < 0 ? -1 : 1;
    for (size_t j = 0; j < 4; ++j)
      bad_rotation +=
          std::fabs(native.rotations[4 * i + j] - sign * decoded.rotations[4 * i + j]) > tolerance.rotation;
    bad_opacity +=
        std::fabs(sigmoid(native.opacity_logits[i]) - sigmoid(decoded.opacity_logits[i])) > tolerance.opacity;
    // Coefficients both have; those only one side has must be zero on it (a file without SH bands
    // beside a source with them is compared on the DC term alone).
    for (size_t k = 0; k < std::min(k_native, k_decoded); ++k)
      for (size_t c = 0; c < 3; ++c) {
        const double a = native.sh[(i * k_native + k) * 3 + c], b = decoded.sh[(i * k_decoded + k) * 3 + c];
        (k == 0 ? bad_dc : bad_rest) += !close(a, b, k == 0 ? tolerance.sh_dc : tolerance.sh_rest);
      }
  }
  EXPECT_EQ(bad_position, 0u) << "positions off by more than " << tolerance.position;
  EXPECT_EQ(bad_scale, 0u) << "log scales off by more than " << tolerance.log_scale;
  EXPECT_EQ(bad_rotation, 0u) << "rotation components off by more than " << tolerance.rotation;
  EXPECT_EQ(bad_opacity, 0u) << "opacities off by more than " << tolerance.opacity;
  EXPECT_EQ(bad_dc, 0u) << "SH DC terms off by more than " << tolerance.sh_dc;
  EXPECT_EQ(bad_rest, 0u) << "SH rest terms off by more than " << tolerance.sh_rest;
}

class SceneFormats : public ::testing::TestWithParam<FormatCase> {};

TEST_P(SceneFormats, GaussiansAndImagesMatchThePlyBesideIt) {
  TILESPLAT_REQUIRE_SHARED_SCENES();
  const FormatCase& c = GetParam();
  const fs::path native_path = testing::shared_scenes() / c.native;
  if (!fs::exists(native_path)) TILESPLAT_SKIP_OR_FAIL(native_path << " not found");
  LoadReport report;
  const GaussianScene native = load_scene(native_path, {}, &report);
  const GaussianScene decoded = load_scene(testing::shared_scenes() / c.decoded);
  EXPECT_EQ(report.dropped, 0u);
  EXPECT_EQ(report.gaussians_in_file, decoded.size());
  EXPECT_FALSE(report.format.empty());
  if (c.decoding) {
    EXPECT_EQ(native.sh_degree, decoded.sh_degree);
  }
  expect_same_gaussians(native, decoded, c.decoding ? Tolerance{} : kQuantized);

  // The images, on the GPU at two views of 480x270.
  const auto views = load_cameras_json(testing::shared_scenes() / "cameras" / (c.cameras + ".json"));
  Renderer& renderer = testing::validated_renderer();
  for (int view : {0, 3}) {
    const Camera camera = resize_camera(views.at(size_t(view)).camera, 480, 270);
    renderer.set_scene(native);
    const RenderImage native_image = renderer.render(camera);
    renderer.set_scene(decoded);
    const RenderImage decoded_image = renderer.render(camera);
    const ImageDifference d = compare_images(native_image, decoded_image);
    std::printf("[ measure  ] %s (%s %s) view %d: against %s PSNR %.2f dB, max abs %.2e\n", c.native.c_str(),
                report.format.c_str(), report.version.c_str(), view, c.decoded.c_str(), d.psnr_db, d.max_abs);
    if (!c.decoding) continue;  // a quantized file against its source: reported, not bounded
    EXPECT_GE(d.psnr_db, 60.0) << "view " << view;
    EXPECT_LE(d.max_abs, 2e-3) << "view " << view;
  }
  EXPECT_EQ(renderer.validation_messages(), 0u);
}

INSTANTIATE_TEST_SUITE_P(Shared, SceneFormats, ::testing::ValuesIn(format_cases()),
                         [](const ::testing::TestParamInfo<FormatCase>& param) {
                           std::string name = param.param.native;
                           for (char& ch : name)
                             if (!std::isalnum(static_cast<unsigned char>(ch))) ch = '_';
                           return name;
                         });

TEST(SceneFormats, FormatAndVersionAreReported) {
  TILESPLAT_REQUIRE_SHARED_SCENES();
  const fs::path formats = testing::shared_scenes() / "formats";
  const std::pair<std::string, std::pair<std::string, std::string>> expected[] = {
      {"playbot_lod6_1873_sh2.v4.spz", {"spz", "4"}},
      {"playbot_lod6_1873_sh2.v3.spz", {"spz", "3"}},
      {"playbot_lod6_1873_sh2.sog", {"sog", "2"}},
      {"playbot_lod6_1873_sh2_sog_unbundled/meta.json", {"sog (unbundled)", "2"}},
      {"playbot_lod6_1873_sh2.compressed.ply", {"compressed ply", ""}},
      {"playbot_lod6_1873_sh2.glb", {"glb", "2.0"}},
      {"../plant_113648.splat", {"splat", ""}},
  };
  for (const auto& [file, format] : expected) {
    LoadReport report;
    load_scene(formats / file, {}, &report);
    EXPECT_EQ(report.format, format.first) << file;
    EXPECT_EQ(report.version, format.second) << file;
  }
}

// ---- malformed files ----

using testing::read_file;

fs::path write_file(const std::string& name, const std::string& bytes) {
  const fs::path path = testing::temp_dir() / name;
  fs::create_directories(path.parent_path());
  std::ofstream(path, std::ios::binary) << bytes;
  return path;
}

std::string gzip(const std::string& data) {
  z_stream stream{};
  deflateInit2(&stream, 9, Z_DEFLATED, 16 + MAX_WBITS, 8, Z_DEFAULT_STRATEGY);
  std::string out(deflateBound(&stream, static_cast<uLong>(data.size())), '\0');
  stream.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(data.data()));
  stream.avail_in = static_cast<uInt>(data.size());
  stream.next_out = reinterpret_cast<Bytef*>(out.data());
  stream.avail_out = static_cast<uInt>(out.size());
  deflate(&stream, Z_FINISH);
  out.resize(stream.total_out);
  deflateEnd(&stream);
  return out;
}

std::string gunzip(const std::string& data) {
  z_stream stream{};
  inflateInit2(&stream, 16 + MAX_WBITS);
  std::string out(1 << 20, '\0');
  stream.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(data.data()));
  stream.avail_in = static_cast<uInt>(data.size());
  stream.next_out = reinterpret_cast<Bytef*>(out.data());
  stream.avail_out = static_cast<uInt>(out.size());
  inflate(&stream, Z_FINISH);
  out.resize(stream.total_out);
  inflateEnd(&stream);
  return out;
}

void put_u32(std::string& bytes, size_t offset, uint32_t value) {
  std::memcpy(bytes.data() + offset, &value, 4);
}

// The entries of a zip (name, bytes), written with libzip.
using ZipEntries = std::vector<std::pair<std::string, std::string>>;

ZipEntries read_zip(const fs::path& path) {
  int error = 0;
  zip_t* archive = zip_open(path.c_str(), ZIP_RDONLY, &error);
  ZipEntries entries;
  for (zip_int64_t i = 0; archive && i < zip_get_num_entries(archive, 0); ++i) {
    zip_stat_t stat;
    zip_stat_index(archive, static_cast<zip_uint64_t>(i), 0, &stat);
    std::string bytes(stat.size, '\0');
    zip_file_t* file = zip_fopen_index(archive, static_cast<zip_uint64_t>(i), 0);
    zip_fread(file, bytes.data(), bytes.size());
    zip_fclose(file);
    entries.push_back({stat.name, bytes});
  }
  if (archive) zip_discard(archive);
  return entries;
}

fs::path write_zip(const std::string& name, const ZipEntries& entries) {
  const fs::path path = testing::temp_dir() / name;
  fs::remove(path);
  int error = 0;
  zip_t* archive = zip_open(path.c_str(), ZIP_CREATE | ZIP_TRUNCATE, &error);
  for (const auto& [entry, bytes] : entries) {
    zip_source_t* source = zip_source_buffer(archive, bytes.data(), bytes.size(), 0);
    zip_file_add(archive, entry.c_str(), source, ZIP_FL_OVERWRITE);
  }
  zip_close(archive);
  return path;
}

std::string& entry(ZipEntries& entries, const std::string& name) {
  for (auto& [entry_name, bytes] : entries)
    if (entry_name == name) return bytes;
  throw std::runtime_error("no zip entry " + name);
}

class FormatErrors : public ::testing::Test {
 protected:
  void SetUp() override {
    TILESPLAT_REQUIRE_SHARED_SCENES();
    formats_ = testing::shared_scenes() / "formats";
    if (!fs::exists(formats_)) TILESPLAT_SKIP_OR_FAIL(formats_ << " not found");
  }
  std::string original(const std::string& file) const { return read_file(formats_ / file); }
  fs::path formats_;
};

TEST_F(FormatErrors, TruncatedFiles) {
  const std::string v4 = original("playcanvas_test_64_sh3.v4.spz");
  testing::expect_scene_error(write_file("cut.v4.spz", v4.substr(0, v4.size() / 2)), {"runs past the end"});
  testing::expect_scene_error(write_file("cut_header.v4.spz", v4.substr(0, 20)), {"truncated SPZ version 4 header"});
  const std::string v3 = original("playcanvas_test_64_sh3.v3.spz");
  testing::expect_scene_error(write_file("cut.v3.spz", v3.substr(0, v3.size() / 2)), {"gzip stream", "64 Gaussians"});
  const std::string compressed = original("playcanvas_test_64_sh3.compressed.ply");
  testing::expect_scene_error(write_file("cut.compressed.ply", compressed.substr(0, compressed.size() - 100)),
               {"truncated"});
  const std::string glb = original("playcanvas_test_64_sh3.glb");
  testing::expect_scene_error(write_file("cut.glb", glb.substr(0, glb.size() - 64)), {"truncated GLB"});
  const std::string sog = original("playcanvas_test_64_sh3.sog");
  testing::expect_scene_error(write_file("cut.sog", sog.substr(0, sog.size() / 2)), {"not a readable zip"});
  const std::string splat = read_file(testing::shared_scenes() / "train_3pts.splat");
  testing::expect_scene_error(write_file("cut.splat", splat.substr(0, splat.size() - 5)), {"not a multiple of 32"});
}

TEST_F(FormatErrors, WrongMagicAndUnknownVersions) {
  std::string v4 = original("playcanvas_test_64_sh3.v4.spz");
  std::string bad_magic = v4;
  bad_magic[3] = 'X';
  testing::expect_scene_error(write_file("magic.spz", bad_magic), {"unrecognized scene format"});
  std::string v5 = v4;
  put_u32(v5, 4, 5);
  testing::expect_scene_error(write_file("v5.spz", v5), {"unsupported SPZ version 5"});
  std::string inner = gunzip(original("playcanvas_test_64_sh3.v3.spz"));
  put_u32(inner, 4, 9);
  testing::expect_scene_error(write_file("v9.spz", gzip(inner)), {"unsupported SPZ version 9"});
  std::string glb = original("playcanvas_test_64_sh3.glb");
  put_u32(glb, 4, 3);
  testing::expect_scene_error(write_file("v3.glb", glb), {"unsupported GLB version 3"});
  ZipEntries sog = read_zip(formats_ / "playcanvas_test_64_sh3.sog");
  std::string& meta = entry(sog, "meta.json");
  meta.replace(meta.find("\"version\":2"), 11, "\"version\":7");
  testing::expect_scene_error(write_zip("v7.sog", sog), {"unsupported SOG version 7"});
}

TEST_F(FormatErrors, CountsThatDisagreeWithTheData) {
  std::string v4 = original("playcanvas_test_64_sh3.v4.spz");
  put_u32(v4, 8, 65);
  testing::expect_scene_error(write_file("count.v4.spz", v4), {"65 Gaussians need"});
  std::string compressed = original("playcanvas_test_64_sh3.compressed.ply");
  const size_t at = compressed.find("element vertex 64");
  compressed.replace(at, 17, "element vertex 65");
  testing::expect_scene_error(write_file("count.compressed.ply", compressed), {"65 Gaussians"});
  ZipEntries sog = read_zip(formats_ / "playcanvas_test_64_sh3.sog");
  std::string& meta = entry(sog, "meta.json");
  meta.replace(meta.find("\"count\":64"), 10, "\"count\":9999");
  testing::expect_scene_error(write_zip("count.sog", sog), {"wrong size for 9999"});
  std::string glb = original("playcanvas_test_64_sh3.glb");
  const size_t count = glb.find("\"count\":64");
  glb.replace(count, 10, "\"count\":99");
  testing::expect_scene_error(write_file("count.glb", glb), {"run past the end"});
}

TEST_F(FormatErrors, SogContainersAndImages) {
  ZipEntries sog = read_zip(formats_ / "playcanvas_test_64_sh3.sog");
  ZipEntries no_meta;
  for (const auto& e : sog)
    if (e.first != "meta.json") no_meta.push_back(e);
  testing::expect_scene_error(write_zip("no_meta.sog", no_meta), {"without meta.json"});

  // A WebP of the wrong size: the 64-Gaussian scene's means in the 1873-Gaussian scene.
  ZipEntries wrong = read_zip(formats_ / "playbot_lod6_1873_sh2.sog");
  entry(wrong, "means_l.webp") = entry(sog, "means_l.webp");
  testing::expect_scene_error(write_zip("wrong_size.sog", wrong), {"means_l.webp", "wrong size"});
  ZipEntries not_webp = sog;
  entry(not_webp, "quats.webp") = "not an image";
  testing::expect_scene_error(write_zip("not_webp.sog", not_webp), {"quats.webp", "not a WebP"});

  // Unbundled, with one image missing.
  const fs::path folder = testing::temp_dir() / "unbundled";
  fs::remove_all(folder);
  fs::copy(formats_ / "playbot_lod6_1873_sh2_sog_unbundled", folder);
  fs::remove(folder / "scales.webp");
  testing::expect_scene_error(folder / "meta.json", {"scales.webp", "cannot be read"});
}

TEST_F(FormatErrors, DecompressionBombsAreRefusedBeforeAllocating) {
  // SPZ v3: a 16-byte header declaring 2^31 Gaussians, gzipped to a few dozen bytes.
  std::string header = gunzip(original("playcanvas_test_64_sh3.v3.spz")).substr(0, 16);
  put_u32(header, 8, 1u << 31);
  testing::expect_scene_error(write_file("bomb.v3.spz", gzip(header + std::string(4096, '\0'))), {"refusing to decompress"});
  // SPZ v4: the same count in a 200-byte file; its TOC's sizes agree with the count.
  std::string v4 = original("playcanvas_test_64_sh3.v4.spz");
  put_u32(v4, 8, 1u << 31);
  testing::expect_scene_error(write_file("bomb.v4.spz", v4), {"declares"});
  // A zip entry whose headers declare 2 GiB for 1 MiB of deflated zeros (about 1 kB).
  ZipEntries sog = read_zip(formats_ / "playcanvas_test_64_sh3.sog");
  entry(sog, "means_l.webp") = std::string(1u << 20, '\0');
  std::string zip = read_file(write_zip("bomb_source.sog", sog));
  size_t patched = 0;
  for (size_t at = 0; at + 46 < zip.size(); ++at) {
    const bool local = zip.compare(at, 4, "PK\x03\x04") == 0, central = zip.compare(at, 4, "PK\x01\x02") == 0;
    if (!local && !central) continue;
    const size_t name_at = at + (local ? 30 : 46);
    uint16_t length = 0;
    std::memcpy(&length, zip.data() + at + (local ? 26 : 28), 2);
    if (zip.compare(name_at, length, "means_l.webp") != 0) continue;
    put_u32(zip, at + (local ? 22 : 24), 0x7fffffffu);
    ++patched;
  }
  ASSERT_EQ(patched, 2u);
  testing::expect_scene_error(write_file("bomb.sog", zip), {"means_l.webp", "refusing to decompress"});
}

TEST(SceneFormatsMemory, ParseSceneReadsTheSameBytesAsLoadScene) {
  TILESPLAT_REQUIRE_SHARED_SCENES();
  for (const std::string file : {"formats/playbot_lod6_1873_sh2.sog", "formats/playbot_lod6_1873_sh2.v4.spz",
                                 "formats/playbot_lod6_1873_sh2.glb", "plant_113648.splat"}) {
    const fs::path path = testing::shared_scenes() / file;
    const std::string bytes = read_file(path);
    const GaussianScene from_file = load_scene(path);
    const GaussianScene from_memory =
        parse_scene(std::as_bytes(std::span(bytes.data(), bytes.size())), path.string());
    EXPECT_EQ(from_file.positions, from_memory.positions) << file;
    EXPECT_EQ(from_file.sh, from_memory.sh) << file;
    EXPECT_EQ(from_file.rotations, from_memory.rotations) << file;
  }
}

// ---------------------------------------------------------------------------------------------
// SceneInParts on an SPZ or a SOG: the packed bytes or texels held, any part decoded from them as load_scene
// decodes it.

void expect_in_parts_is_loaded(const fs::path& path) {
  SCOPED_TRACE(path.filename().string());
  LoadReport loaded_report, in_parts_report;
  const GaussianScene loaded = load_scene(path, {}, &loaded_report);
  const SceneInParts in_parts = SceneInParts::open(path, {}, &in_parts_report);
  ASSERT_EQ(in_parts.size(), loaded.size());
  EXPECT_EQ(in_parts.sh_degree(), loaded.sh_degree);
  EXPECT_FALSE(in_parts.has_normals());
  const Bounds bounds = compute_bounds(loaded);
  for (int a = 0; a < 3; ++a) {
    EXPECT_EQ(in_parts.bounds().min[a], bounds.min[a]);
    EXPECT_EQ(in_parts.bounds().max[a], bounds.max[a]);
  }
  EXPECT_EQ(in_parts.bounds().radius, bounds.radius);
  testing::expect_identical_scenes(in_parts.load(), loaded);
  EXPECT_EQ(in_parts_report.format, loaded_report.format);
  EXPECT_EQ(in_parts_report.version, loaded_report.version);
  EXPECT_EQ(in_parts_report.gaussians_in_file, loaded_report.gaussians_in_file);
  EXPECT_EQ(in_parts_report.ignored_properties, loaded_report.ignored_properties);
  EXPECT_EQ(in_parts_report.dropped, loaded_report.dropped);
  EXPECT_EQ(in_parts_report.summary(), loaded_report.summary());
  // Any part of it: test_part_rows.cpp (the renderer's parts gather them).
  // Read in parts is chosen by the Gaussians' size as floats: the header's count at its SH degree.
  EXPECT_EQ(SceneInParts::whole_scene_bytes(path),
            loaded_report.gaussians_in_file * (11 + 3 * size_t(loaded.sh_coefficients())) * sizeof(float));
}

TEST(SceneInPartsFormats, HoldsTheGaussiansLoadSceneReads) {
  TILESPLAT_REQUIRE_SHARED_SCENES();
  const fs::path formats = testing::shared_scenes() / "formats";
  for (const std::string file : {"playbot_lod6_1873_sh2.v4.spz", "playbot_lod6_1873_sh2.v3.spz",
                                 "playcanvas_test_64_sh3.v4.spz", "playcanvas_test_64_sh3.v3.spz"})
    expect_in_parts_is_loaded(formats / file);
  expect_in_parts_is_loaded(testing::shared_scenes() / "biker_152746.spz");  // SH degree 0
  for (const std::string file : {"playbot_lod6_1873_sh2.sog", "playcanvas_test_64_sh3.sog",
                                 "playbot_lod6_1873_sh2_sog_unbundled/meta.json"})
    expect_in_parts_is_loaded(formats / file);
  expect_in_parts_is_loaded(testing::shared_scenes() / "playbot_lod0_500000.sog");
  // SPZ versions 2 and 3 may be stored uncompressed: the same bytes without gzip.
  expect_in_parts_is_loaded(
      write_file("plain.v3.spz", gunzip(read_file(formats / "playcanvas_test_64_sh3.v3.spz"))));
  // A binary PLY's size is its floats; a file neither PLY nor SPZ, or missing, tells nothing.
  const fs::path ply = testing::shared_scenes() / "playbot_lod0_500000_sh2.ply";
  EXPECT_EQ(SceneInParts::whole_scene_bytes(ply), fs::file_size(ply));
  EXPECT_EQ(SceneInParts::whole_scene_bytes(formats / "playbot_lod6_1873_sh2.glb"), 0u);
  EXPECT_EQ(SceneInParts::whole_scene_bytes(testing::temp_dir() / "no_such.spz"), 0u);
}

// Whatever load_scene refuses, SceneInParts refuses with the same message (naming the file): cuts of a
// version 3 and a version 4 file, an unknown version. A file too short to be told an SPZ is not a PLY
// (MappedPlyErrors).
TEST_F(FormatErrors, AnSpzInPartsRefusesWhatLoadSceneRefuses) {
  for (const std::string file : {"playcanvas_test_64_sh3.v4.spz", "playcanvas_test_64_sh3.v3.spz"}) {
    const std::string bytes = original(file);
    size_t refused = 0, cuts = 0;
    for (size_t length = 4; length < bytes.size(); length += 37) {  // from the magic on: an SPZ by content
      const fs::path cut = write_file("cut_in_parts.spz", bytes.substr(0, length));
      const std::string expected = testing::error_of<SceneError>([&] { load_scene(cut); });
      EXPECT_EQ(testing::error_of<SceneError>([&] { SceneInParts::open(cut); }), expected)
          << file << " cut to " << length;
      refused += expected != "(no exception)";  // a gzip stream cut in its trailer still holds every Gaussian
      ++cuts;
    }
    EXPECT_GE(refused + 2, cuts) << file;
  }
  std::string v5 = original("playcanvas_test_64_sh3.v4.spz");
  put_u32(v5, 4, 5);
  const fs::path unknown = write_file("v5_in_parts.spz", v5);
  EXPECT_EQ(testing::error_of<SceneError>([&] { SceneInParts::open(unknown); }),
            testing::error_of<SceneError>([&] { load_scene(unknown); }));
}

// A SOG whose codebook holds a value no float holds: its Gaussians dropped as load_scene drops them (or,
// strict, refused with its message), read in parts as read whole.
TEST_F(FormatErrors, ASogInPartsDropsWhatLoadSceneDrops) {
  ZipEntries entries = read_zip(formats_ / "playbot_lod6_1873_sh2.sog");
  nlohmann::json meta = nlohmann::json::parse(entry(entries, "meta.json"));
  for (size_t b = 0; b < 256; b += 2) meta["scales"]["codebook"][b] = 1e39;  // past float's range
  entry(entries, "meta.json") = meta.dump();
  const fs::path path = write_zip("overflowing.sog", entries);
  LoadReport loaded_report;
  const size_t kept = load_scene(path, {}, &loaded_report).size();
  ASSERT_GT(loaded_report.dropped, 0u);
  ASSERT_GT(kept, 0u);
  expect_in_parts_is_loaded(path);
  LoadOptions strict;
  strict.strict = true;
  const std::string refused = testing::error_of<SceneError>([&] { load_scene(path, strict); });
  EXPECT_NE(refused.find("strict mode"), std::string::npos) << refused;
  EXPECT_EQ(testing::error_of<SceneError>([&] { SceneInParts::open(path, strict); }), refused);
}

// The float64 reference found it: denormal quaternions are the identity, as float32 normalization
// in gsplat and the original rasterizer makes them, not a direction renormalized in double.
TEST(SceneFormatsPostProcessing, DenormalQuaternionsBecomeTheIdentity) {
  std::string ply =
      "ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty float y\nproperty float z\n"
      "property float f_dc_0\nproperty float f_dc_1\nproperty float f_dc_2\nproperty float opacity\n"
      "property float scale_0\nproperty float scale_1\nproperty float scale_2\nproperty float rot_0\n"
      "property float rot_1\nproperty float rot_2\nproperty float rot_3\nend_header\n"
      "0 0 0 0 0 0 1 0 0 0 1e-40 2e-40 0 -1e-39\n"
      "0 0 0 0 0 0 1 0 0 0 1e-40 1 0 0\n";
  const GaussianScene scene = load_scene(write_file("denormal.ply", ply));
  ASSERT_EQ(scene.size(), 2u);
  EXPECT_EQ(std::vector<float>(scene.rotations.begin(), scene.rotations.begin() + 4),
            (std::vector<float>{1, 0, 0, 0}));
  // One normal component among denormals is an ordinary direction.
  EXPECT_FLOAT_EQ(scene.rotations[5], 1.0f);
}

}  // namespace
}  // namespace tilesplat
