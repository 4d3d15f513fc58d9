# Warnings every tilesplat target builds with.
function(tilesplat_set_warnings target)
  target_compile_options(${target} PRIVATE -Wall -Wextra -Wpedantic -Wshadow -Wconversion
                         -Wno-sign-conversion -Wnon-virtual-dtor -Wold-style-cast
                         # Vulkan structs are initialised as `VkFoo info{VK_STRUCTURE_TYPE_FOO}`.
                         -Wno-missing-field-initializers)
endfunction()
