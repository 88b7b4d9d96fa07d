// --background: what lies behind every output (the encoded image, the views, the quilt and the
// previews), composited under it with premultiplied alpha: C' = C + (1 - a) B and a' = a + (1 - a) a_B,
// B premultiplied.
// - A colour R,G,B[,A] (linear): B = (R A, G A, B A, A), the same behind every voxel. The encoded image
//   is composited per subpixel with each subpixel's own alpha (AR, AG, AB): the same as compositing
//   every view over the colour and encoding the result.
// - `environment`: the environment (--environment) drawn on a plane at a chosen depth
//   (output/backdrop.h), alpha 1, different in every view. Its layers are made per rig: one backdrop
//   voxel per view voxel, and the backdrop volume encoded by the pipeline's own encoder for the encoded
//   image, composited per subpixel as above.
#pragma once
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace pmr {

// Where --background environment is drawn (--background-depth): the focal plane (no disparity), at
// infinity, or at a view-space depth in scene units.
struct BackdropDepth {
  enum class Kind { Focal, Infinity, Distance };
  Kind kind = Kind::Focal;
  double distance = 0.0;  // Kind::Distance: > 0
  bool operator==(const BackdropDepth& o) const { return kind == o.kind && distance == o.distance; }
};

// "focal", "inf" or a finite depth > 0. Throws pmr::Error naming --background-depth otherwise.
BackdropDepth parse_backdrop_depth(const std::string& text);
// "focal", "inf" or the depth (%.9g).
std::string to_string(const BackdropDepth& depth);

// One frame's backdrop (half RGBA, premultiplied, alpha 1): `volume` one pixel per view voxel (the
// pipeline's view-major layout), `display` one per display pixel (empty without an encoded image).
struct BackdropLayers {
  std::vector<uint16_t> volume, display;
};

struct Background {
  double r = 0.0, g = 0.0, b = 0.0, a = 0.0;     // linear; alpha 0: transparent, nothing changes
  bool environment = false;                      // --background environment (the colour is unused)
  BackdropDepth depth;                           // environment: where it is drawn
  std::shared_ptr<const BackdropLayers> layers;  // environment: the frame's backdrop, set per frame
  bool transparent() const { return !environment && a == 0.0; }
};

// "environment", "R,G,B" (opaque) or "R,G,B,A": finite non-negative colour, alpha in [0, 1]. Throws
// pmr::Error naming --background otherwise.
Background parse_background(const std::string& text);

// Half RGBA pixels (premultiplied) over the background, in place. With the environment, `pixels` is
// its layers' volume's size.
void composite_rgba(uint16_t* rgba_half, size_t pixels, const Background& bg);

// The encoded image over the background, in place: colour channel k of each pixel with its subpixel's
// alpha sub_alpha[3 * pixel + k]; those alphas composited too, and A their mean. With the environment,
// `pixels` is its layers' display's size.
void composite_encoded(uint16_t* rgba_half, uint16_t* sub_alpha, size_t pixels, const Background& bg);

}  // namespace pmr
