// The fuzz build compiles Debian's stb_image (the same header libstb.a is built
// from) with the sanitizers and coverage, so that the fuzzer sees inside the
// decoder; the linker then takes stb_image from here and not from libstb.a.
#define STB_IMAGE_IMPLEMENTATION
#include <stb/stb_image.h>
