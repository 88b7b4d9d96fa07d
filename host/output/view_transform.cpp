#include "output/view_transform.h"

#include <Imath/half.h>
#include <OpenColorIO/OpenColorIO.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <functional>
#include <thread>

#include "pmr/error.h"
#include "pmr/output.h"
#include "pmr/printable.h"

namespace OCIO = OCIO_NAMESPACE;

namespace pmr {

enum class TransformKind { Standard, DisplayReferred, Managed };

struct ViewTransform::Impl {
  TransformKind kind = TransformKind::Standard;
  ViewTransformRecord record;
  OCIO::ConstCPUProcessorRcPtr cpu;  // Managed only
};

namespace {

constexpr size_t kRowPixels = 4096;  // pixels transformed per call (a few cache lines of floats)

float half_to_float(uint16_t bits) {
  half h;
  h.setBits(bits);
  return float(h);
}
uint16_t float_to_half(float v) { return half(v).bits(); }

std::string quoted_list(int count, const std::function<const char*(int)>& name) {
  std::string out;
  for (int i = 0; i < count; ++i) out += (i ? ", '" : "'") + printable_text(name(i) ? name(i) : "") + "'";
  return out.empty() ? "(none)" : out;
}

// The config's name for `wanted` ("" = its default), or a UsageError naming the valid ones.
std::string check_name(const std::string& kind, const std::string& option, const std::string& wanted,
                       const char* fallback, int count, const std::function<const char*(int)>& name) {
  if (wanted.empty()) return fallback ? fallback : "";
  for (int i = 0; i < count; ++i)
    if (name(i) && wanted == name(i)) return wanted;
  throw UsageError("unknown " + option + " '" + printable_text(wanted) + "': the config's " + kind + " are " +
                   quoted_list(count, name));
}

OCIO::ConstConfigRcPtr load_config(const std::string& path) {
  OCIO::SetLoggingLevel(OCIO::LOGGING_LEVEL_NONE);  // its problems reach the user as our one error line
  try {
    OCIO::ConstConfigRcPtr config = OCIO::Config::CreateFromFile(path.c_str());
    config->validate();
    return config;
  } catch (const OCIO::Exception& e) {
    throw Error("cannot use the OpenColorIO config " + printable_text(path) + ": " + printable_text(e.what()));
  }
}

// The names the options give, checked against the config (Blender's own chain: exposure in scene
// linear, the look into its process space, the display's view with its own looks bypassed, then gamma).
ViewTransformRecord resolve_names(const OCIO::ConstConfigRcPtr& c, const ViewTransformOptions& o) {
  ViewTransformRecord r;
  r.config = o.config;
  r.display = check_name("displays", "--display-device", o.display, c->getDefaultDisplay(), c->getNumDisplays(),
                         [&](int i) { return c->getDisplay(i); });
  const char* display = r.display.c_str();
  r.view =
      check_name("views of display '" + printable_text(r.display) + "'", "--view", o.view, c->getDefaultView(display),
                 c->getNumViews(display), [&](int i) { return c->getView(display, i); });
  if (!o.look.empty() && o.look != "None")
    r.look = check_name("looks", "--look", o.look, nullptr, c->getNumLooks(),
                        [&](int i) { return c->getLookNameByIndex(i); });
  // the role resolved to the colour space it names, which is what the sidecar records
  const OCIO::ConstColorSpaceRcPtr role = c->getColorSpace(OCIO::ROLE_SCENE_LINEAR);
  const char* linear = role ? role->getName() : nullptr;
  if (!o.colorspace.empty() && !c->getColorSpace(o.colorspace.c_str()))
    check_name("colour spaces", "--colorspace", o.colorspace, nullptr, c->getNumColorSpaces(),
               [&](int i) { return c->getColorSpaceNameByIndex(i); });
  r.colorspace = o.colorspace.empty() ? (linear ? linear : "") : o.colorspace;
  if (r.colorspace.empty())
    throw UsageError("the OpenColorIO config " + printable_text(o.config) +
                     " has no scene_linear role: name pmr's colour space (linear Rec. 709) with --colorspace");
  r.exposure = o.exposure, r.gamma = o.gamma;
  return r;
}

OCIO::ConstCPUProcessorRcPtr make_processor(const OCIO::ConstConfigRcPtr& c, const ViewTransformRecord& r) {
  auto group = OCIO::GroupTransform::Create();
  std::string input = r.colorspace;
  if (r.exposure != 0.0) {
    const double g = std::exp2(r.exposure);
    const double m[16] = {g, 0, 0, 0, 0, g, 0, 0, 0, 0, g, 0, 0, 0, 0, 1};
    auto to_linear = OCIO::ColorSpaceTransform::Create();
    to_linear->setSrc(input.c_str());
    to_linear->setDst(OCIO::ROLE_SCENE_LINEAR);
    group->appendTransform(to_linear);
    auto gain = OCIO::MatrixTransform::Create();
    gain->setMatrix(m);
    group->appendTransform(gain);
    input = OCIO::ROLE_SCENE_LINEAR;
  }
  bool look_applied = false;
  if (!r.look.empty()) {
    const char* space = OCIO::LookTransform::GetLooksResultColorSpace(c, c->getCurrentContext(), r.look.c_str());
    if (space && *space) {
      auto look = OCIO::LookTransform::Create();
      look->setSrc(input.c_str());
      look->setDst(space);
      look->setLooks(r.look.c_str());
      group->appendTransform(look);
      input = space, look_applied = true;
    }
  }
  auto view = OCIO::DisplayViewTransform::Create();
  view->setSrc(input.c_str());
  view->setDisplay(r.display.c_str());
  view->setView(r.view.c_str());
  view->setLooksBypass(look_applied);
  group->appendTransform(view);
  if (r.gamma != 1.0) {
    const double e = 1.0 / r.gamma, value[4] = {e, e, e, 1.0};
    auto exponent = OCIO::ExponentTransform::Create();
    exponent->setValue(value);
    group->appendTransform(exponent);
  }
  return c->getProcessor(group)->getDefaultCPUProcessor();
}

}  // namespace

ViewTransform::ViewTransform() : impl_(std::make_unique<Impl>()) {}

ViewTransform::ViewTransform(const ViewTransformOptions& o) : ViewTransform() {
  if (!(o.gamma > 0.0 && o.gamma <= 100.0) || !(std::abs(o.exposure) <= 64.0))
    throw UsageError("--view-exposure must be an EV from -64 to 64 and --view-gamma in (0, 100]");
  if (o.config.empty()) {
    if (!o.display.empty() || !o.view.empty() || !o.look.empty() || !o.colorspace.empty())
      throw UsageError(
          "--display-device, --view, --look and --colorspace name parts of an OpenColorIO config: "
          "give one with --ocio CONFIG (or $OCIO)");
    impl_->record.display = "sRGB", impl_->record.view = "Standard";
    impl_->record.exposure = o.exposure, impl_->record.gamma = o.gamma;
    return;
  }
  const OCIO::ConstConfigRcPtr config = load_config(o.config);
  impl_->record = resolve_names(config, o);
  try {
    impl_->cpu = make_processor(config, impl_->record);
  } catch (const OCIO::Exception& e) {
    throw Error("cannot build the OpenColorIO view transform from " + printable_text(o.config) + ": " +
                printable_text(e.what()));
  }
  impl_->kind = TransformKind::Managed;
}

ViewTransform::~ViewTransform() = default;
ViewTransform::ViewTransform(ViewTransform&&) noexcept = default;
ViewTransform& ViewTransform::operator=(ViewTransform&&) noexcept = default;

ViewTransform ViewTransform::display_referred() {
  ViewTransform t;
  t.impl_->kind = TransformKind::DisplayReferred;
  return t;
}

bool ViewTransform::mixes_channels() const { return impl_->kind == TransformKind::Managed; }

bool ViewTransform::is_standard() const {
  const ViewTransformRecord& r = impl_->record;
  return impl_->kind == TransformKind::Standard && r.exposure == 0.0 && r.gamma == 1.0;
}

void ViewTransform::apply(float* rgba, size_t pixels) const {
  const Impl& m = *impl_;
  if (m.kind == TransformKind::Managed) {
    OCIO::PackedImageDesc image(rgba, long(pixels), 1, 4);
    m.cpu->apply(image);
    return;
  }
  if (m.kind == TransformKind::DisplayReferred) return;
  const double gain = std::exp2(m.record.exposure), e = 1.0 / m.record.gamma;
  for (size_t i = 0; i < pixels; ++i)
    for (int c = 0; c < 3; ++c) {
      const double v = srgb_encode(gain * double(rgba[4 * i + size_t(c)]));
      rgba[4 * i + size_t(c)] = float(e == 1.0 ? v : std::pow(v, e));
    }
}

const ViewTransformRecord& ViewTransform::record() const { return impl_->record; }

std::vector<uint16_t> shown_colours(const uint16_t* rgba_half, size_t pixels, const Background& background,
                                    const ViewTransform& transform) {
  std::vector<uint16_t> out(rgba_half, rgba_half + pixels * 4);
  composite_rgba(out.data(), pixels, background);
  auto part = [&](size_t begin, size_t end) {
    std::vector<float> rgba;
    for (size_t p0 = begin; p0 < end; p0 += kRowPixels) {
      const size_t n = std::min(kRowPixels, end - p0);
      rgba.resize(n * 4);
      for (size_t i = 0; i < n * 4; ++i) rgba[i] = half_to_float(out[p0 * 4 + i]);
      transform.apply(rgba.data(), n);
      for (size_t i = 0; i < n; ++i) {
        for (size_t c = 0; c < 3; ++c)
          out[(p0 + i) * 4 + c] = float_to_half(std::min(1.0f, std::max(0.0f, rgba[i * 4 + c])));  // NaN -> 0
        out[(p0 + i) * 4 + 3] = float_to_half(1.0f);
      }
    }
  };
  const size_t threads = std::max(1u, std::min(16u, std::thread::hardware_concurrency()));
  std::vector<std::thread> pool;
  const size_t share = (pixels + threads - 1) / threads;
  for (size_t t = 1; t < threads; ++t)
    if (t * share < pixels) pool.emplace_back(part, t * share, std::min(pixels, (t + 1) * share));
  part(0, std::min(pixels, share));
  for (std::thread& th : pool) th.join();
  return out;
}

ViewTransform make_view_transform(ViewTransformOptions options) {
  if (options.config.empty())
    if (const char* env = std::getenv("OCIO"); env && *env) options.config = env;
  return ViewTransform(options);
}

}  // namespace pmr
