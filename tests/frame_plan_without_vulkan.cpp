// The frame's plan is a value: frame/frame_plan.h reaches no Vulkan header, so that what plans frames
// (and its tests) needs no device and no Vulkan SDK. This file fails to compile when it does.
#include "frame/frame_plan.h"

#ifdef VK_HEADER_VERSION
#error "frame/frame_plan.h includes a Vulkan header (directly or through another): the plan must stay a value"
#endif
