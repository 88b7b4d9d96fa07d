// The view transform of the display-referred products (PNG previews: the panel image, the center view,
// the quilt): scene-linear Rec. 709 -> the values a display shows, through OpenColorIO when a config is
// given (--ocio, or $OCIO), else "Standard", the sRGB transfer curve with a clip, as Blender names it.
// EXRs never pass through it: they stay scene-linear (docs/COLOUR.md).
#pragma once
#include <memory>
#include <string>
#include <vector>

#include "output/background.h"

namespace pmr {

struct ViewTransformOptions {
  std::string config;      // an OpenColorIO config file; "" = none ("Standard")
  std::string display;     // the display device; "" = the config's default display
  std::string view;        // the view transform; "" = the display's default view
  std::string look;        // a look, or several as OpenColorIO writes them ("A, B"); "" = none
  std::string colorspace;  // pmr's pixels as the config names them; "" = the scene_linear role
  double exposure = 0.0;   // EV, display side (Blender's View exposure): x 2^EV before the view
  double gamma = 1.0;      // display side (Blender's View gamma): ^(1 / gamma) after the display
};

// What was applied, as the sidecar records it (shading of no other product depends on it).
struct ViewTransformRecord {
  std::string config;  // "" without OpenColorIO
  std::string display, view, look, colorspace;
  double exposure = 0.0, gamma = 1.0;
};

class ViewTransform {
 public:
  // "Standard": the sRGB curve, clipped, without exposure or gamma (today's previews, byte for byte).
  ViewTransform();
  // Opens the config and checks every name; one pmr::UsageError (exit 2) listing the valid names for an
  // unknown display, view, look or colour space, pmr::Error for a config that does not load.
  explicit ViewTransform(const ViewTransformOptions& options);
  ~ViewTransform();
  ViewTransform(ViewTransform&&) noexcept;
  ViewTransform& operator=(ViewTransform&&) noexcept;

  // Values that are already display-referred (the panel image encoded from transformed views): only
  // clipped to [0, 1].
  static ViewTransform display_referred();

  // Standard without exposure or gamma: the PNG writer's table of every half value applies.
  bool is_standard() const;
  // Whether an output channel may depend on the other input channels (an OpenColorIO transform may: a
  // 3D LUT, a matrix): then it does not commute with the encoder's choice of one channel per subpixel.
  bool mixes_channels() const;
  // Transforms `pixels` RGBA floats in place (straight colour; alpha untouched): the result is the
  // display's encoded value, not yet clipped. Thread-safe.
  void apply(float* rgba, size_t pixels) const;
  const ViewTransformRecord& record() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// What a panel shows of premultiplied half RGBA pixels: each over the background (over black when it is
// transparent), through the transform, clipped to [0, 1]; half RGBA with alpha 1. On every core.
std::vector<uint16_t> shown_colours(const uint16_t* rgba_half, size_t pixels, const Background& background,
                                    const ViewTransform& transform);

// The transform the options ask for: with no config in the options, $OCIO when it is set and not empty.
ViewTransform make_view_transform(ViewTransformOptions options);

}  // namespace pmr
