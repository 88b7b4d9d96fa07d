// Includes Debian's stb_image with its implementation, its functions static to the including file and
// its warnings silenced. Define the decoder selection (STBI_ONLY_PNG, STBI_ONLY_HDR, ...) and limits
// (STBI_MAX_DIMENSIONS) before including this; each including .cpp gets its own private copy, so two
// files may select different decoders.
#ifndef STB_IMAGE_STATIC
#define STB_IMAGE_STATIC
#endif
#define STB_IMAGE_IMPLEMENTATION
#define STBI_NO_STDIO  // pmr reads files itself (input_files.h: confined, regular, budgeted)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wunused-function"
#pragma GCC diagnostic ignored "-Wunused-parameter"
#pragma GCC diagnostic ignored "-Wsign-compare"
#pragma GCC diagnostic ignored "-Wmissing-field-initializers"
#pragma GCC diagnostic ignored "-Wimplicit-fallthrough"
#include <stb/stb_image.h>
#pragma GCC diagnostic pop
