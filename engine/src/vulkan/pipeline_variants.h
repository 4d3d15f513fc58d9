// The pipelines of one shader, one per variant: the specialization constants (and the shader's texel
// twin) a frame's settings pick. Each is made the first time a frame needs it and kept for the life of
// its pass, since making one costs a driver compile.
#pragma once

#include <map>
#include <utility>

#include "vulkan/compute_pipeline.h"

namespace tilesplat::vk {

template <typename Variant, typename Pipeline = ComputePipeline>
class PipelineVariants {
 public:
  // The variant's pipeline; `make()` makes it when there is none yet.
  template <typename Make>
  Pipeline& get(const Variant& variant, Make&& make) {
    auto it = pipelines_.find(variant);
    if (it == pipelines_.end()) it = pipelines_.emplace(variant, std::forward<Make>(make)()).first;
    return it->second;
  }

 private:
  std::map<Variant, Pipeline> pipelines_;
};

}  // namespace tilesplat::vk
