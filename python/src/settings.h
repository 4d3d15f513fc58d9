// tilesplat.RenderSettings: the C++ RenderSettings as Python sees it, its fields by the names of
// Renderer.render()'s keywords. The fields are one table (settings_bindings.cpp) that the class's
// properties, its constructor, replace(), __repr__ and the keyword overrides of render() and
// render_reference() all read, so that a field, its default (the C++ default) and its check exist once.
#pragma once
#include "bindings.h"
#include "tilesplat/render_settings.h"

namespace tilesplat::python {

// `base` (null: the defaults) with `overrides` applied by field name, each checked as its property's
// setter checks it. A name that is no field raises TypeError as Python does for an unexpected keyword
// argument of `function`.
RenderSettings settings_with(const RenderSettings* base, const nb::kwargs& overrides, const char* function);

}  // namespace tilesplat::python
