/* glint — stb_image's decoders compiled into the image fuzzer (instrumented, so the fuzzer sees
 * the Radiance HDR decoder's branches) in place of Debian's shared library. */
#define STB_IMAGE_IMPLEMENTATION
#include <stb/stb_image.h>
