// compare_exr A.exr B.exr: whether two renders agree, for the install check (an example's image
// against tilesplat-render's). Prints PSNR and max abs over RGB and A; exits 0 when every RGBA value
// is equal, 1 when they differ, 2 when a file cannot be read or the sizes differ.
#include <cstdio>
#include <exception>

#include "tilesplat/image.h"

int main(int argc, char** argv) {
  if (argc != 3) {
    std::fprintf(stderr, "usage: compare_exr A.exr B.exr\n");
    return 2;
  }
  try {
    const tilesplat::RenderImage a = tilesplat::read_exr(argv[1]);
    const tilesplat::RenderImage b = tilesplat::read_exr(argv[2]);
    const tilesplat::ImageDifference d = tilesplat::compare_images(a, b);
    std::printf("%s vs %s: %dx%d, PSNR %.2f dB, max abs %.3g (alpha %.3g)\n", argv[1], argv[2], a.width,
                a.height, d.psnr_db, d.max_abs, d.max_abs_alpha);
    return d.max_abs == 0 && d.max_abs_alpha == 0 ? 0 : 1;
  } catch (const std::exception& error) {
    std::fprintf(stderr, "compare_exr: %s\n", error.what());
    return 2;
  }
}
