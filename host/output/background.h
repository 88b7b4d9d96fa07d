// --background R,G,B[,A]: a linear colour behind every output (the encoded image, the views, the quilt
// and the previews), composited over it with premultiplied alpha: C' = C + (1 - a) B a_B and
// a' = a + (1 - a) a_B. The encoded image is composited per subpixel with each subpixel's own alpha
// (AR, AG, AB): the same as compositing every view over the background and encoding the result, since
// the background is the same in every view.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

namespace pmr {

struct Background {
  double r = 0.0, g = 0.0, b = 0.0, a = 0.0;  // linear; alpha 0: transparent, nothing changes
  bool transparent() const { return a == 0.0; }
};

// "R,G,B" (opaque) or "R,G,B,A": finite non-negative colour, alpha in [0, 1]. Throws pmr::Error naming
// --background otherwise.
Background parse_background(const std::string& text);

// Half RGBA pixels (premultiplied) over the background, in place.
void composite_rgba(uint16_t* rgba_half, size_t pixels, const Background& bg);

// The encoded image over the background, in place: colour channel k of each pixel with its subpixel's
// alpha sub_alpha[3 * pixel + k]; those alphas composited too, and A their mean.
void composite_encoded(uint16_t* rgba_half, uint16_t* sub_alpha, size_t pixels, const Background& bg);

}  // namespace pmr
