/// @file
/// Writing your own key sort: the extension point behind RenderSettings::sort.
///
/// A frame sorts twice: the visible Gaussians by view depth, then the (tile, Gaussian) pairs by
/// tile id. Both sorts go through one strategy, chosen by name. A strategy registered here runs in
/// every frame that names it, in the sort micro-benchmark (Renderer::sort_keys) and in
/// `tilesplat-bench`, which can load it from a plugin (`--sort-plugin FILE.so`), beside the
/// built-in strategies, so that its time and its images are compared with theirs.
///
/// The contract a strategy must honour, the same as the built-in ones:
/// - **Order**: ascending keys; equal keys keep their input order (a stable sort). The two sorts of
///   a frame together then equal one sort by (tile, depth, Gaussian index), and the image is
///   bit-identical to the other strategies'. `tilesplat-bench` reports any difference.
/// - **Data**: SortBuffers::count key/value pairs (a GPU value, see SortBuffers) in `keys`/`values`;
///   values move with their keys. `keys_alt`/`values_alt` are scratch of the same capacity. The
///   sorted pairs end in either pair of buffers: record() says which.
/// - **Recording**: record() records into the frame's command buffer and submits nothing. The engine
///   puts a memory barrier (compute and transfer writes made visible to compute, transfer and
///   indirect reads) before the strategy's commands and after them; between its own passes the
///   strategy places its own barriers.
///
/// This header includes the Vulkan headers (through tilesplat/vulkan_interop.h): a strategy
/// records Vulkan commands.
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "tilesplat/export.h"
#include "tilesplat/vulkan_interop.h"

namespace tilesplat {

/// The device a strategy is created for: the renderer's, which owns these handles. A strategy
/// creates its pipelines and scratch buffers on `device` and destroys them in its destructor.
struct SortDevice {
  VkPhysicalDevice physical_device = VK_NULL_HANDLE;  ///< for memory types and limits
  VkDevice device = VK_NULL_HANDLE;                   ///< Vulkan 1.2 with bufferDeviceAddress and shaderInt64
  uint32_t queue_family = 0;                          ///< the family the frame's commands run on
  uint32_t subgroup_size = 0;  ///< the compute subgroup size (8 on lavapipe, 32 on NVIDIA)
};

/// The pairs of one sort. Every buffer was created with storage, transfer source and destination,
/// indirect and shader-device-address usage, so a shader may reach it by its device address.
struct SortBuffers {
  VkBuffer keys = VK_NULL_HANDLE;          ///< the input keys: `capacity` keys of key_bytes each
  VkBuffer values = VK_NULL_HANDLE;        ///< the input values: `capacity` uint32_t
  VkBuffer keys_alt = VK_NULL_HANDLE;      ///< scratch keys, the size of `keys`
  VkBuffer values_alt = VK_NULL_HANDLE;    ///< scratch values, the size of `values`
  VkDeviceAddress keys_address = 0;        ///< device address of `keys`
  VkDeviceAddress values_address = 0;      ///< device address of `values`
  VkDeviceAddress keys_alt_address = 0;    ///< device address of `keys_alt`
  VkDeviceAddress values_alt_address = 0;  ///< device address of `values_alt`
  /// The buffer, offset and device address of the key count, one uint32_t written on the GPU before
  /// the sort runs (it is at most `capacity`). Recording cannot read it: a GPU strategy reads it in
  /// its shaders or dispatches indirectly from values it derives from it.
  VkBuffer count_buffer = VK_NULL_HANDLE;
  VkDeviceSize count_offset = 0;      ///< byte offset of the count in count_buffer
  VkDeviceAddress count_address = 0;  ///< device address of the count
  uint32_t capacity = 0;              ///< pairs each buffer holds; at most the max_keys of the last reserve()
  /// 4: keys are uint32_t; 8: keys are uint64_t (little endian). A frame uses 4-byte keys when every
  /// key of the sort fits in 32 bits.
  uint32_t key_bytes = 8;
  uint32_t key_bits = 64;  ///< only the low key_bits bits of a key vary; the others are zero
  /// True when the low 32 key bits are the bits of a positive float (a view depth, which therefore
  /// sorts as an unsigned integer), false for plain integer keys.
  bool depth_in_low_bits = false;
};

/// A key sort written outside the library. Subclass it, register a factory for it by name
/// (register_sort_strategy or a plugin), and name it in RenderSettings::sort.
///
/// A renderer creates one object per strategy name on first use and keeps it until the renderer is
/// destroyed; it calls the object from the thread that renders, never from two threads at once.
class ExternalSortStrategy {
 public:
  virtual ~ExternalSortStrategy() = default;

  /// Sizes the scratch the strategy needs for sorts of up to `max_keys` pairs. Called before any
  /// record() of a larger sort and outside command buffer recording: scratch replaced here is not in
  /// use by the GPU (the renderer waits for its frames first).
  virtual void reserve(uint32_t max_keys) = 0;

  /// Records the sort of `buffers` into `command_buffer`, which is in the recording state and whose
  /// pipeline bindings and push constants the strategy may change. Returns true when the sorted
  /// pairs are in keys_alt/values_alt, false when they are in keys/values. Exceptions propagate out
  /// of the render call that recorded.
  virtual bool record(VkCommandBuffer command_buffer, const SortBuffers& buffers) = 0;

  /// Device memory the strategy holds, in bytes, for FrameStats::device_bytes.
  virtual uint64_t device_bytes() const { return 0; }
};

/// Makes a strategy for a device. May throw; the render call that needed it fails with the exception.
using SortStrategyFactory = std::function<std::unique_ptr<ExternalSortStrategy>(const SortDevice& device)>;

/// Registers a sort strategy under `name` for the whole process: sort_strategies() lists it after the
/// built-in ones, sort_strategy_is_exact() is true for it (the contract above), and every renderer
/// makes it when a frame first names it. Thread-safe.
/// @throws std::invalid_argument when `name` is empty, contains a comma or whitespace, or is taken.
TILESPLAT_API void register_sort_strategy(const std::string& name, SortStrategyFactory factory);

/// A sort strategy registered for as long as this object lives, as register_sort_strategy does (and
/// throwing as it does); destroying it removes the name from sort_strategies(), so that a test or a
/// short-lived tool leaves nothing behind for the rest of the process. A renderer that already made
/// the strategy keeps its instance; a frame that names it afterwards fails as for an unknown name.
class TILESPLAT_API ScopedSortStrategy {
 public:
  /// Registers `factory` under `name`.
  ScopedSortStrategy(std::string name, SortStrategyFactory factory);
  /// Removes the registration (nothing when moved from).
  ~ScopedSortStrategy();
  ScopedSortStrategy(const ScopedSortStrategy&) = delete;             ///< one owner per registration
  ScopedSortStrategy& operator=(const ScopedSortStrategy&) = delete;  ///< one owner per registration
  /// Takes over the registration; `other` then owns none.
  ScopedSortStrategy(ScopedSortStrategy&& other) noexcept;
  /// Removes this object's registration and takes over `other`'s.
  ScopedSortStrategy& operator=(ScopedSortStrategy&& other) noexcept;
  /// The registered name ("" when moved from).
  const std::string& name() const { return name_; }

 private:
  std::string name_;
};

/// What a sort plugin registers its strategies with.
class SortPluginRegistry {
 public:
  /// Registers one strategy, as register_sort_strategy does (and throws as it does).
  virtual void add(const std::string& name, SortStrategyFactory factory) = 0;

 protected:
  ~SortPluginRegistry() = default;
};

/// The name of the function a sort plugin exports, with C linkage and the signature
/// `void tilesplat_sort_plugin_v1(tilesplat::SortPluginRegistry& registry)`. A plugin needs no
/// symbol of libtilesplat (everything it uses from this header is inline or virtual), so it loads
/// into a program linked to the static library as well as the shared one; it must be built with the
/// same C++ standard library as the program.
#define TILESPLAT_SORT_PLUGIN_ENTRY "tilesplat_sort_plugin_v1"

/// Loads a sort plugin (a shared object, dlopen) and registers its strategies. The plugin stays
/// loaded for the life of the process. Returns the names it registered. Thread-safe.
/// @throws std::runtime_error naming the file when it cannot be loaded, lacks the entry function or
/// registers nothing; std::invalid_argument when a name it registers is taken.
TILESPLAT_API std::vector<std::string> load_sort_plugin(const std::filesystem::path& path);

}  // namespace tilesplat
