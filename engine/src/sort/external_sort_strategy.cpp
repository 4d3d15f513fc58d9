// Sort strategies from outside the library (tilesplat/sort_strategy.h): an adapter that lets a
// user's ExternalSortStrategy stand where the built-in strategies stand, their registration, and
// the loading of sort plugins.
#include <dlfcn.h>

#include <filesystem>
#include <map>
#include <memory>
#include <mutex>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "sort/sort_strategy.h"
#include "tilesplat/sort_strategy.h"
#include "vulkan/compute_pipeline.h"

namespace tilesplat {
namespace {

// A user's strategy behind the engine's SortStrategy interface. It hands the user the raw buffers
// and fences the user's commands with barriers, so that what the frame wrote before the sort (the
// keys, the count) is visible to them and what they wrote is visible to the passes after it.
class ExternalSortAdapter final : public SortStrategy {
 public:
  ExternalSortAdapter(std::string name, std::unique_ptr<ExternalSortStrategy> strategy)
      : name_(std::move(name)), strategy_(std::move(strategy)) {
    if (!strategy_) throw std::runtime_error("the factory of sort strategy '" + name_ + "' returned nothing");
  }

  std::string name() const override { return name_; }
  void reserve(uint32_t max_keys) override { strategy_->reserve(max_keys); }
  uint64_t device_bytes() const override { return strategy_->device_bytes(); }

  bool record(vk::CommandStream& stream, SortInput& input) override {
    const KeyBuffers& kb = input.keys;
    SortBuffers buffers;
    buffers.keys = kb.keys.handle();
    buffers.values = kb.values.handle();
    buffers.keys_alt = kb.keys_alt.handle();
    buffers.values_alt = kb.values_alt.handle();
    buffers.keys_address = kb.keys.address();
    buffers.values_address = kb.values.address();
    buffers.keys_alt_address = kb.keys_alt.address();
    buffers.values_alt_address = kb.values_alt.address();
    buffers.count_buffer = input.state.handle();
    buffers.count_offset = input.state_offset;  // SortState::count is the block's first word
    buffers.count_address = input.state.address() + input.state_offset;
    buffers.capacity = kb.capacity;
    buffers.key_bytes = kb.key_bytes();
    buffers.key_bits = input.key_bits;
    buffers.depth_in_low_bits = input.depth_in_low_bits;

    const VkCommandBuffer cmd = stream.cmd();
    vk::barrier(cmd);
    const bool in_alt = strategy_->record(cmd, buffers);
    vk::barrier(cmd);
    return in_alt;
  }

 private:
  std::string name_;
  std::unique_ptr<ExternalSortStrategy> strategy_;
};

// Plugins loaded so far, by canonical path, with the names each registered: loading one again
// returns its names instead of registering them twice.
std::mutex plugins_mutex;
std::map<std::filesystem::path, std::vector<std::string>>& loaded_plugins() {
  static std::map<std::filesystem::path, std::vector<std::string>> plugins;
  return plugins;
}

class PluginRegistry final : public SortPluginRegistry {
 public:
  void add(const std::string& name, SortStrategyFactory factory) override {
    register_sort_strategy(name, std::move(factory));
    names.push_back(name);
  }
  std::vector<std::string> names;
};

}  // namespace

void register_sort_strategy(const std::string& name, SortStrategyFactory factory) {
  if (!factory) throw std::invalid_argument("sort strategy '" + name + "' has no factory");
  add_sort_strategy(name, /*exact=*/true, [name, factory = std::move(factory)](vk::Context& ctx) {
    const SortDevice device{ctx.physical_device(), ctx.device(), ctx.queue_family(),
                            ctx.limits().subgroup_size};
    return std::make_unique<ExternalSortAdapter>(name, factory(device));
  });
}

ScopedSortStrategy::ScopedSortStrategy(std::string name, SortStrategyFactory factory)
    : name_(std::move(name)) {
  register_sort_strategy(name_, std::move(factory));
}

ScopedSortStrategy::~ScopedSortStrategy() {
  if (!name_.empty()) remove_sort_strategy(name_);
}

ScopedSortStrategy::ScopedSortStrategy(ScopedSortStrategy&& other) noexcept : name_(std::move(other.name_)) {
  other.name_.clear();
}

ScopedSortStrategy& ScopedSortStrategy::operator=(ScopedSortStrategy&& other) noexcept {
  if (this != &other) {
    if (!name_.empty()) remove_sort_strategy(name_);
    name_ = std::move(other.name_);
    other.name_.clear();
  }
  return *this;
}

std::vector<std::string> load_sort_plugin(const std::filesystem::path& path) {
  const std::string prefix = "cannot load sort plugin " + path.string() + ": ";
  std::error_code error;
  if (!std::filesystem::is_regular_file(path, error)) {
    throw std::runtime_error(prefix + (std::filesystem::exists(path, error) ? "it is not a regular file"
                                                                            : "the file does not exist"));
  }
  const std::filesystem::path canonical = std::filesystem::canonical(path);

  const std::lock_guard lock(plugins_mutex);
  if (const auto loaded = loaded_plugins().find(canonical); loaded != loaded_plugins().end())
    return loaded->second;
  // An absolute path: dlopen searches the library path for a name without a slash.
  void* handle = ::dlopen(canonical.c_str(), RTLD_NOW | RTLD_LOCAL);
  if (!handle) throw std::runtime_error(prefix + ::dlerror());
  using Entry = void (*)(SortPluginRegistry&);
  const auto entry = reinterpret_cast<Entry>(::dlsym(handle, TILESPLAT_SORT_PLUGIN_ENTRY));
  if (!entry) {
    ::dlclose(handle);
    throw std::runtime_error(prefix + "it exports no function " TILESPLAT_SORT_PLUGIN_ENTRY
                                      " (declare it extern \"C\" and visible)");
  }
  PluginRegistry registry;
  entry(registry);  // the plugin stays loaded: its factories and vtables are used from now on
  if (registry.names.empty()) throw std::runtime_error(prefix + "it registered no sort strategy");
  loaded_plugins().emplace(canonical, registry.names);
  return registry.names;
}

}  // namespace tilesplat
